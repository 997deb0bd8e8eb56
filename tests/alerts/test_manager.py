"""Alert logic without ROS: hysteresis, grinding and forecast alerts, configuration errors, and the
series form against a plain message-by-message reference written here from the documented rules."""

from __future__ import annotations

import itertools
from collections import deque

import numpy as np
import pytest

from rail_monitor.alerts.config import (
    ALERT_SPECS,
    KIND_GRINDING_DUE,
    KIND_GRINDING_FORECAST,
    KIND_INPUT_REJECTED,
    KIND_NOISE_LIMIT,
    KIND_SQUEAL,
    RISK_NAMES,
    alert_config,
)
from rail_monitor.alerts.manager import AlertManager
from rail_monitor.core.errors import ConfigError
from rail_monitor.core.timeutil import NS_PER_DAY

DAY = NS_PER_DAY


def _manager(**over) -> AlertManager:
    return AlertManager(alert_config({f"alerts.{k}": v for k, v in over.items()}, lead_time_days=60.0))


# One message is a series of length 1.
def _noise(m, t, level):
    return m.on_noise(np.array([t]), "cnossos", {"lpafmax_dba": np.array([level])})


def _squeal(m, t, risk):
    return m.on_squeal(np.array([t]), np.array([risk]))


def _train_pass(m, t, rejected):
    return m.on_train_passes(np.array([t]), np.array([rejected]))


def _state(m, t, lam, amp, thr, days, due, due_ns):
    return m.on_states(np.array([t]), lam, np.array([amp]), thr, np.array([days]), np.array([due]),
                       np.array([due_ns]))


def test_noise_alert_needs_the_hysteresis_band_to_clear():
    m = _manager(noise_limit_dba=88.0, noise_hysteresis_db=3.0, noise_window_passes=5)
    raised = _noise(m, 1, 88.5)
    assert [(a.kind, a.key, a.active) for a in raised] == [(KIND_NOISE_LIMIT, "cnossos", True)]
    # 86 dB is under the limit but inside the 3 dB band: never clears, however long it lasts
    assert not any(_noise(m, 2 + i, 86.0) for i in range(50))
    # five passes below 85 dB fill the window: it clears on the fifth, not before
    events = [_noise(m, 100 + i, 80.0) for i in range(5)]
    assert [len(e) for e in events] == [0, 0, 0, 0, 1] and not events[-1][0].active
    assert events[-1][0].raised_ns == 1 and not m.standing


def test_squeal_alert_raises_on_a_full_window_share_and_clears_below_the_lower_share():
    m = _manager(squeal_window_passes=10, squeal_raise_share=0.3, squeal_clear_share=0.1)
    # two of the first three passes squeal: the window is not full, so no alert yet
    assert not any(_squeal(m, i, r) for i, r in enumerate([3, 3, 0]))
    out = [_squeal(m, 3 + i, 0) for i in range(6)] + [_squeal(m, 9, 2)]  # 3 of 10 at the tenth pass
    assert out[-1] and out[-1][0].kind == KIND_SQUEAL and out[-1][0].active
    flat = [_squeal(m, 10 + i, 0) for i in range(10)]
    cleared = [i for i, e in enumerate(flat) if e]
    # the share falls to 1/10 when the second of the first two squeals leaves: at the 2nd quiet pass
    assert cleared == [1] and not flat[1][0].active


def test_rejected_inputs_alert():
    m = _manager(rejected_window_passes=20, rejected_raise_share=0.1, rejected_clear_share=0.0)
    ev = [_train_pass(m, i, i in (3, 5)) for i in range(10)]
    assert [i for i, e in enumerate(ev) if e] == [5] and ev[5][0].kind == KIND_INPUT_REJECTED
    later = [_train_pass(m, 10 + i, False) for i in range(20)]
    assert [i for i, e in enumerate(later) if e] == [15]  # the rejection at 5 leaves the window of 20


def test_grinding_due_per_band_and_forecast_superseded_then_cleared_by_grinding():
    m = _manager(grinding_clear_fraction=0.9, forecast_clear_factor=1.2)
    lam = np.array([0.05, 0.063])
    thr = np.array([10e-6, 10e-6])
    e = _state(m, 1 * DAY, lam, [5e-6, 6e-6], thr, 40.0, True, 41 * DAY)
    assert [(a.kind, a.active, a.due_ns) for a in e] == [(KIND_GRINDING_FORECAST, True, 41 * DAY)]
    e = _state(m, 30 * DAY, lam, [9e-6, 10.5e-6], thr, 0.0, True, 30 * DAY)
    kinds = {(a.kind, a.key, a.active) for a in e}
    assert kinds == {(KIND_GRINDING_DUE, "0.0630m", True), (KIND_GRINDING_FORECAST, "forecast", False)}
    # just below the threshold (inside the hysteresis band): still standing
    assert not _state(m, 31 * DAY, lam, [9e-6, 9.5e-6], thr, 0.5, True, 31 * DAY)
    # after grinding: cleared, and the forecast is far beyond 1.2 x 60 days
    e = _state(m, 32 * DAY, lam, [4e-6, 4e-6], thr, 500.0, False, 532 * DAY)
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


class _Reference:
    """The alert rules of rail_monitor.alerts, message by message with deques: an independent
    statement of the same rules (events as (kind, key, active, stamp, raised, due))."""

    def __init__(self, cfg: dict) -> None:
        self.c = {**{k: s.default for k, s in _SPEC_DEFAULTS.items()}, **cfg}
        self.standing: dict[tuple[int, str], list] = {}   # (kind, key) -> [raised_ns, due_ns]
        self.windows: dict[str, deque] = {}

    def _set(self, active: bool, kind: int, key: str, t: int, due: int = 0) -> list[tuple]:
        old = self.standing.get((kind, key))
        if active == (old is not None):
            if old is not None and due and due != old[1]:
                old[1] = due
            return []
        if active:
            self.standing[(kind, key)] = [t, due]
            return [(kind, key, True, t, t, due)]
        del self.standing[(kind, key)]
        return [(kind, key, False, t, old[0], 0)]

    def _window(self, name: str, n: int, flags: tuple[bool, bool]) -> tuple[int, int, int]:
        w = self.windows.setdefault(name, deque(maxlen=n))
        w.append(flags)
        return sum(o for o, _ in w), sum(r for _, r in w), len(w)

    def _toggle(self, kind: int, key: str, t: int, can_raise: bool, can_clear: bool) -> list[tuple]:
        if (kind, key) in self.standing:
            return self._set(False, kind, key, t) if can_clear else []
        return self._set(True, kind, key, t) if can_raise else []

    def noise(self, t: int, level: float) -> list[tuple]:
        c, limit = self.c, self.c["noise_limit_dba"]
        over, near, _ = self._window("noise", c["noise_window_passes"],
                                     (level > limit, level > limit - c["noise_hysteresis_db"]))
        return self._toggle(KIND_NOISE_LIMIT, "cnossos", t, over >= c["noise_raise_count"],
                            near <= c["noise_clear_count"])

    def _share(self, name: str, kind: int, key: str, t: int, hit: bool, full: bool) -> list[tuple]:
        c, n = self.c, self.c[f"{name}_window_passes"]
        over, _, held = self._window(name, n, (hit, hit))
        can_raise = (held == n or not full) and over >= max(n * c[f"{name}_raise_share"], 1)
        return self._toggle(kind, key, t, can_raise, over <= c[f"{name}_clear_share"] * held)

    def squeal(self, t: int, risk: int) -> list[tuple]:
        hit = risk >= RISK_NAMES.index(self.c["squeal_min_risk"])
        return self._share("squeal", KIND_SQUEAL, "site", t, hit, full=True)

    def train_pass(self, t: int, rejected: bool) -> list[tuple]:
        return self._share("rejected", KIND_INPUT_REJECTED, "train_pass", t, rejected, full=False)

    def state(self, t: int, lam, amp, thr, days: float, due: bool, due_ns: int) -> list[tuple]:
        out = []
        for z, z_thr, lam_b in zip(amp, thr, lam, strict=True):
            key = f"{lam_b:.4f}m"
            if z >= z_thr:
                out += self._set(True, KIND_GRINDING_DUE, key, t)
            elif z < self.c["grinding_clear_fraction"] * z_thr:
                out += self._set(False, KIND_GRINDING_DUE, key, t)
        due_standing = any(kind == KIND_GRINDING_DUE for kind, _ in self.standing)
        if due and not due_standing:
            out += self._set(True, KIND_GRINDING_FORECAST, "forecast", t, due_ns)
        elif due_standing or days > self.c["forecast_clear_factor"] * 60.0:
            out += self._set(False, KIND_GRINDING_FORECAST, "forecast", t)
        return out


_SPEC_DEFAULTS = {s.name: s for s in ALERT_SPECS}


def _as_tuple(a) -> tuple:
    return a.kind, a.key, a.active, a.stamp_ns, a.raised_ns, a.due_ns


@pytest.mark.parametrize("seed", range(6))
def test_series_inputs_follow_the_rules_message_by_message_in_any_chunking(seed):
    """Each input's series form against the reference above, fed one message at a time: the same
    events (kind, key, raised/cleared, times) and the same standing alerts (with the forecast's due
    time), with the series cut into random chunks (the windows carry over) after a prefix fed one
    message at a time (series of length 1)."""
    rng = np.random.default_rng(seed)
    n, lam = 600, np.array([0.04, 0.05, 0.063, 0.08])
    s = _streams(rng, n, len(lam))
    ref, many = _Reference(SMALL), _manager(**SMALL)
    ref_events = {kind: [] for kind in range(1, 6)}
    for k in range(n):
        t = int(s["stamp"][k])
        for e in (ref.train_pass(t, bool(s["rejected"][k])) + ref.squeal(t, int(s["risk"][k]))
                  + ref.noise(t, float(s["level"][k]))
                  + ref.state(t, lam, s["amp"][k], s["thr"], float(s["days"][k]), bool(s["due"][k]),
                              int(s["due_ns"][k]))):
            ref_events[e[0]].append(e)
    got = {kind: [] for kind in range(1, 6)}
    prefix = 50
    cuts = np.unique(np.concatenate([np.arange(prefix + 1), [n], rng.integers(prefix, n, 12)]))
    for a, b in itertools.pairwise(cuts):
        t = s["stamp"][a:b]
        for e in (many.on_train_passes(t, s["rejected"][a:b]) + many.on_squeal(t, s["risk"][a:b])
                  + many.on_noise(t, "cnossos", {"lpafmax_dba": s["level"][a:b]})
                  + many.on_states(t, lam, s["amp"][a:b], s["thr"], s["days"][a:b], s["due"][a:b],
                                   s["due_ns"][a:b])):
            got[e.kind].append(_as_tuple(e))
    for kind in ref_events:  # streams do not interact: each kind's events in their own order
        assert got[kind] == ref_events[kind], kind
        assert len(ref_events[kind]) >= 4, kind  # the streams do exercise every alert
    assert {k: (a.raised_ns, a.due_ns) for k, a in many.standing.items()} == \
        {k: tuple(v) for k, v in ref.standing.items()}


def test_bands_closer_than_the_key_resolution_get_distinct_keys():
    """Two bands that format to the same 0.1 mm key still get alerts of their own."""
    m = _manager()
    lam, thr = np.array([0.05, 0.05000001]), np.array([10e-6, 10e-6])
    events = _state(m, 1, lam, [11e-6, 11e-6], thr, 0.0, True, 1)
    due = [a.key for a in events if a.kind == KIND_GRINDING_DUE]
    assert len(due) == 2 and len(set(due)) == 2


def _residual(i: int, train: str, excess: float, vehicles=("V1", "V2", "V3"), loudest="", loudest_db=0.0,
              drift=float("nan"), model="cnossos", squeal=(False, 0)):
    from rail_monitor.measured.residuals import Residual

    return Residual(i * DAY // 100, train, model, np.zeros(0), np.zeros(0), 0.0, 0.0, 0.0, excess, 0.0, drift, 2.0,
                    0.6, excess, loudest, loudest_db, squeal[0], tuple(vehicles), squeal[1])


def test_wheel_defect_alerts_name_the_vehicle_count_repeats_and_clear_with_hysteresis():
    from rail_monitor.alerts.config import KIND_WHEEL_DEFECT

    m = _manager(wheel_defect_raise_db=6.0, wheel_defect_clear_db=3.0, wheel_defect_vehicle_db=2.0)
    seq = [_residual(0, "T1", 1.0),
           _residual(1, "T1", 7.0, loudest="V2", loudest_db=5.0),       # vehicle V2 named: raised
           _residual(2, "T2", 4.0, vehicles=("V2", "V9")),                # between the thresholds: stays
           _residual(3, "T3", 8.0, loudest="V2", loudest_db=6.5),        # again: counted, no new event
           _residual(4, "T4", 9.0),                                       # no vehicle named: the train
           _residual(5, "T5", 1.0, vehicles=("V2", "V7")),                # V2 quiet again: cleared
           _residual(6, "T6", 2.0, loudest="V8", loudest_db=7.5),        # a loud vehicle, train not: raised
           _residual(7, "T4", 20.0, model="mechanics")]                   # the other model: ignored
    events = m.on_residuals(seq)
    assert [(e.key, e.active) for e in events] == [("vehicle V2", True), ("train T4", True), ("vehicle V2", False),
                                                  ("vehicle V8", True)]
    assert all(e.kind == KIND_WHEEL_DEFECT for e in events)
    assert m.offences == {"vehicle V2": 2, "train T4": 1, "vehicle V8": 1}
    assert "flagged 1 time(s)" in events[0].summary and events[3].value == 7.5
    assert set(m.standing) == {(KIND_WHEEL_DEFECT, "train T4"), (KIND_WHEEL_DEFECT, "vehicle V8")}



def test_a_long_run_keeps_counts_not_every_event_or_every_train_flagged():
    """A box running for years: events are handed over by take_events and forgotten, raises and
    clears stay counted; the repeat-offender counts keep the most flagged keys, not one per train."""
    from rail_monitor.alerts import manager

    m = _manager(wheel_defect_raise_db=6.0, wheel_defect_clear_db=3.0, wheel_defect_vehicle_db=2.0)
    n = 2 * manager.OFFENDERS_KEPT
    # A named vehicle flagged every tenth pass and quiet five passes later (raised, then cleared),
    # and a new train flagged on each of the others (0.8 n keys).
    seq = [_residual(i, f"T{i}", 9.0, loudest="V1", loudest_db=5.0) if i % 10 == 0
           else _residual(i, f"T{i}", 1.0, vehicles=("V1",)) if i % 10 == 5 else _residual(i, f"T{i}", 9.0)
           for i in range(n)]
    returned = m.on_residuals(seq)
    taken = m.take_events()
    assert taken == returned and m.events == [] and m.take_events() == []
    assert m.raised == sum(e.active for e in taken) and m.cleared == sum(not e.active for e in taken) > 0
    assert len(m.offences) <= manager.OFFENDERS_KEPT
    assert m.offences["vehicle V1"] == (n + 9) // 10  # the repeat offender keeps its true count

def test_the_drift_alert_raises_on_the_baseline_rise_and_clears_below_its_hysteresis():
    from rail_monitor.alerts.config import KIND_NOISE_DRIFT

    m = _manager(drift_raise_db=3.0, drift_clear_db=1.5)
    drift = [float("nan"), 0.5, 2.9, 3.1, 2.0, 1.6, 1.4, 3.5]
    events = m.on_residuals([_residual(i, f"T{i}", 0.0, drift=d) for i, d in enumerate(drift)])
    assert [(e.kind, e.active, e.stamp_ns) for e in events] == [
        (KIND_NOISE_DRIFT, True, 3 * DAY // 100), (KIND_NOISE_DRIFT, False, 6 * DAY // 100),
        (KIND_NOISE_DRIFT, True, 7 * DAY // 100)]
    with pytest.raises(ConfigError, match="drift alert needs hysteresis"):
        _manager(drift_raise_db=2.0, drift_clear_db=2.0)


def test_squeal_measured_but_not_predicted_or_the_reverse_raises_on_its_share_of_the_window():
    from rail_monitor.alerts.config import KIND_SQUEAL_MISMATCH

    m = _manager(squeal_mismatch_window_passes=10, squeal_mismatch_raise_share=0.3, squeal_mismatch_clear_share=0.1,
                 squeal_min_risk="medium")
    # 10 agreeing passes, then 4 measured squealing with risk low (not predicted), then agreement again
    seq = [(True, 3), (False, 0)] * 5 + [(True, 1)] * 4 + [(False, 1)] * 10
    events = m.on_residuals([_residual(i, f"T{i}", 0.0, squeal=q) for i, q in enumerate(seq)])
    assert [(e.kind, e.key, e.active, e.stamp_ns) for e in events] == [
        (KIND_SQUEAL_MISMATCH, "measured, not predicted", True, 12 * DAY // 100),
        (KIND_SQUEAL_MISMATCH, "measured, not predicted", False, 22 * DAY // 100)]
    assert m.on_residuals([_residual(30, "T", 0.0, squeal=(True, 3), model="mechanics")] * 20) == []


def test_the_stations_squeal_share_over_a_window_raises_at_the_sites_limit_and_clears_below_it():
    """Issue 55: what the station hears, whatever the model says: 10 measured passes of which 2 squeal
    (passes 2 and 6), then 3 squealing in a row: the first of them makes 3 of the last 10 (30 %,
    raised); then quiet ones until at most 1 of the last 10 squeals (pass 21: cleared)."""
    from rail_monitor.alerts.config import KIND_SQUEAL_MEASURED

    m = _manager(squeal_measured_window_passes=10, squeal_measured_raise_share=0.3, squeal_measured_clear_share=0.1)
    seq = [(i in (2, 6), 0) for i in range(10)] + [(True, 0)] * 3 + [(False, 0)] * 10
    events = m.on_residuals([_residual(i, f"T{i}", 0.0, squeal=q) for i, q in enumerate(seq)])
    got = [(e.kind, e.key, e.active, e.stamp_ns) for e in events if e.kind == KIND_SQUEAL_MEASURED]
    assert got == [(KIND_SQUEAL_MEASURED, "site", True, 10 * DAY // 100),
                   (KIND_SQUEAL_MEASURED, "site", False, 21 * DAY // 100)]
    assert all("squeal measured" in e.summary for e in events if e.kind == KIND_SQUEAL_MEASURED)
    with pytest.raises(ConfigError, match="measured squeal alert needs hysteresis"):
        _manager(squeal_measured_raise_share=0.1, squeal_measured_clear_share=0.1)
