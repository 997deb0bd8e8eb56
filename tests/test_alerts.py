"""Alert logic without ROS: hysteresis, grinding and forecast alerts, configuration errors."""

from __future__ import annotations

import itertools

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


def _streams(rng: np.random.Generator, n: int, bands: int) -> dict:
    """Random inputs near every threshold of _manager(**SMALL), so that each alert toggles often."""
    thr = np.full(bands, 10e-6)
    slow = np.repeat(rng.random(n // 20 + 1), 20)[:n]  # spells of more and fewer hits
    days = rng.choice([0.0, 10.0, 50.0, 65.0, 80.0, 500.0], n)
    return {
        "stamp": np.cumsum(rng.integers(1, 10**9, n)),
        "rejected": rng.random(n) < 0.3 * slow,
        "risk": np.where(rng.random(n) < slow, rng.integers(2, 4, n), rng.integers(0, 2, n)),
        "level": 80.0 + 12.0 * rng.random(n) * (0.5 + slow),
        "thr": thr,
        "amp": thr * (0.5 + 0.65 * rng.random((n, bands)) * (0.6 + 0.6 * slow[:, None])),
        "days": days, "due": (days <= 60.0) | (rng.random(n) < 0.05),
        "due_ns": rng.choice([0, 7 * DAY, 9 * DAY, 11 * DAY], n),
    }


SMALL = dict(noise_window_passes=5, noise_raise_count=2, noise_clear_count=0, noise_hysteresis_db=3.0,
             squeal_window_passes=7, squeal_raise_share=0.4, squeal_clear_share=0.15,
             rejected_window_passes=6, rejected_raise_share=0.3, rejected_clear_share=0.1)


@pytest.mark.parametrize("seed", range(6))
def test_series_inputs_give_the_events_and_state_of_one_message_at_a_time(seed):
    """Batch mode's series form of each input against the node's one-message form (the reference):
    the same events (every field, in order) and the same standing alerts and windows afterwards,
    with the series cut into random chunks (the windows carry over) after a shared prefix."""
    rng = np.random.default_rng(seed)
    n, lam = 600, np.array([0.04, 0.05, 0.063, 0.08])
    s = _streams(rng, n, len(lam))
    one, many = _manager(**SMALL), _manager(**SMALL)

    def by_message(m, k):
        t = int(s["stamp"][k])
        return (m.on_train_pass(t, bool(s["rejected"][k])) + m.on_squeal(t, int(s["risk"][k]))
                + m.on_noise(t, "cnossos", {"lpafmax_dba": float(s["level"][k])})
                + m.on_state(t, lam, s["amp"][k], s["thr"], float(s["days"][k]), bool(s["due"][k]),
                             int(s["due_ns"][k])))

    prefix = 50
    for k in range(prefix):
        by_message(one, k)
        by_message(many, k)
    ref = {kind: [] for kind in range(1, 6)}
    for k in range(prefix, n):
        for e in by_message(one, k):
            ref[e.kind].append(e)
    got = {kind: [] for kind in range(1, 6)}
    cuts = np.unique(np.concatenate([[prefix, n], rng.integers(prefix, n, 12)]))
    for a, b in itertools.pairwise(cuts):
        t = s["stamp"][a:b]
        for e in (many.on_train_pass_series(t, s["rejected"][a:b]) + many.on_squeal_series(t, s["risk"][a:b])
                  + many.on_noise_series(t, "cnossos", {"lpafmax_dba": s["level"][a:b]})
                  + many.on_states(t, lam, s["amp"][a:b], s["thr"], s["days"][a:b], s["due"][a:b],
                                   s["due_ns"][a:b])):
            got[e.kind].append(e)
    for kind in ref:  # streams do not interact: each kind's events in their own order
        assert got[kind] == ref[kind], kind
        assert len(ref[kind]) >= 4, kind  # the streams do exercise every alert
    assert many.standing == one.standing
    for w1, w2 in ((one._squeal, many._squeal), (one._rejected, many._rejected),
                   (one._noise["cnossos"], many._noise["cnossos"])):
        assert (list(w1.flags), w1.over, w1.near) == (list(w2.flags), w2.over, w2.near)
