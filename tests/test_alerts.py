"""Alert logic without ROS: hysteresis, grinding and forecast alerts, configuration errors."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.alerts import (
    KIND_GRINDING_DUE,
    KIND_GRINDING_FORECAST,
    KIND_INPUT_REJECTED,
    KIND_NOISE_LIMIT,
    KIND_SQUEAL,
    AlertManager,
    alert_config,
)
from rail_monitor.errors import ConfigError

DAY = 86_400 * 10**9


def _manager(**over) -> AlertManager:
    return AlertManager(alert_config({f"alerts.{k}": v for k, v in over.items()}, lead_time_days=60.0))


def test_noise_alert_needs_the_hysteresis_band_to_clear():
    m = _manager(noise_limit_dba=88.0, noise_hysteresis_db=3.0, noise_window_passes=5)
    raised = m.on_noise(1, "cnossos", {"lpafmax_dba": 88.5})
    assert [(a.kind, a.key, a.active) for a in raised] == [(KIND_NOISE_LIMIT, "cnossos", True)]
    # 86 dB is under the limit but inside the 3 dB band: never clears, however long it lasts
    assert not any(m.on_noise(2 + i, "cnossos", {"lpafmax_dba": 86.0}) for i in range(50))
    # five passes below 85 dB fill the window: it clears on the fifth, not before
    events = [m.on_noise(100 + i, "cnossos", {"lpafmax_dba": 80.0}) for i in range(5)]
    assert [len(e) for e in events] == [0, 0, 0, 0, 1] and not events[-1][0].active
    assert events[-1][0].raised_ns == 1 and not m.standing


def test_squeal_alert_raises_on_a_full_window_share_and_clears_below_the_lower_share():
    m = _manager(squeal_window_passes=10, squeal_raise_share=0.3, squeal_clear_share=0.1)
    # two of the first three passes squeal: the window is not full, so no alert yet
    assert not any(m.on_squeal(i, r) for i, r in enumerate([3, 3, 0]))
    out = [m.on_squeal(3 + i, 0) for i in range(6)] + [m.on_squeal(9, 2)]  # 3 of 10 at the tenth pass
    assert out[-1] and out[-1][0].kind == KIND_SQUEAL and out[-1][0].active
    flat = [m.on_squeal(10 + i, 0) for i in range(10)]
    cleared = [i for i, e in enumerate(flat) if e]
    # the share falls to 1/10 when the second of the first two squeals leaves: at the 2nd quiet pass
    assert cleared == [1] and not flat[1][0].active


def test_rejected_inputs_alert():
    m = _manager(rejected_window_passes=20, rejected_raise_share=0.1, rejected_clear_share=0.0)
    ev = [m.on_train_pass(i, i in (3, 5)) for i in range(10)]
    assert [i for i, e in enumerate(ev) if e] == [5] and ev[5][0].kind == KIND_INPUT_REJECTED
    later = [m.on_train_pass(10 + i, False) for i in range(20)]
    assert [i for i, e in enumerate(later) if e] == [15]  # the rejection at 5 leaves the window of 20


def test_grinding_due_per_band_and_forecast_superseded_then_cleared_by_grinding():
    m = _manager(grinding_clear_fraction=0.9, forecast_clear_factor=1.2)
    lam = np.array([0.05, 0.063])
    thr = np.array([10e-6, 10e-6])
    e = m.on_state(1 * DAY, lam, [5e-6, 6e-6], thr, 40.0, True, 41 * DAY)
    assert [(a.kind, a.active, a.due_ns) for a in e] == [(KIND_GRINDING_FORECAST, True, 41 * DAY)]
    e = m.on_state(30 * DAY, lam, [9e-6, 10.5e-6], thr, 0.0, True, 30 * DAY)
    kinds = {(a.kind, a.key, a.active) for a in e}
    assert kinds == {(KIND_GRINDING_DUE, "0.0630m", True), (KIND_GRINDING_FORECAST, "forecast", False)}
    # just below the threshold (inside the hysteresis band): still standing
    assert not m.on_state(31 * DAY, lam, [9e-6, 9.5e-6], thr, 0.5, True, 31 * DAY)
    # after grinding: cleared, and the forecast is far beyond 1.2 x 60 days
    e = m.on_state(32 * DAY, lam, [4e-6, 4e-6], thr, 500.0, False, 532 * DAY)
    assert [(a.kind, a.active) for a in e] == [(KIND_GRINDING_DUE, False)] and not m.standing


@pytest.mark.parametrize("over", [{"noise_clear_count": 1, "noise_raise_count": 1},
                                  {"squeal_clear_share": 0.3, "squeal_raise_share": 0.2},
                                  {"noise_raise_count": 30, "noise_window_passes": 20},
                                  {"noise_metric": "lmax"}])
def test_config_without_hysteresis_or_out_of_range_is_refused(over):
    with pytest.raises(ConfigError):
        _manager(**over)
