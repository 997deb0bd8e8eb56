"""The squeal model's drift alert (rail_monitor.alerts.squeal_drift, issue 55): a friction state's
measured squeal share outside the share the model predicted, fit window after fit window on one
side, raises it; a window inside clears it; windows with too few passes are not judged."""

from __future__ import annotations

from rail_monitor.alerts.config import KIND_SQUEAL_DRIFT, SEVERITY_INFO, SEVERITY_WARNING, alert_config
from rail_monitor.alerts.manager import AlertManager
from rail_monitor.core.timeutil import NS_PER_DAY

WEEK = 7 * NS_PER_DAY
BAND = (0.10, 0.20)  # the predicted share's P10-P90 of every window here


def _manager(**over) -> AlertManager:
    return AlertManager(alert_config({f"alerts.{k}": v for k, v in over.items()}, lead_time_days=60.0))


def _fits(m: AlertManager, shares: list[tuple[str, int, int]]) -> list:
    """One fit a week, each with one state's window (state, passes, flagged squealing)."""
    events = []
    for week, (state, n, k) in enumerate(shares, 1):
        events += m.on_squeal_fit(week * WEEK, [(state, n, k, *BAND)])
    return events


def test_three_windows_running_above_raise_and_one_inside_clears():
    """Defaults (3 windows, 30 passes): above P90 twice, inside, above three times: raised at the
    sixth fit (not the second run of two), with the measured share and P90 as value and threshold;
    a window inside clears it at the seventh."""
    m = _manager()
    events = _fits(m, [("dry", 100, 30), ("dry", 100, 25), ("dry", 100, 15), ("dry", 100, 30), ("dry", 100, 28),
                       ("dry", 100, 26), ("dry", 100, 14)])
    assert [(e.stamp_ns // WEEK, e.active) for e in events] == [(6, True), (7, False)]
    up, down = events
    assert (up.kind, up.key, up.severity, up.value, up.threshold) == (KIND_SQUEAL_DRIFT, "dry", SEVERITY_WARNING,
                                                                      0.26, 0.20)
    assert "more than predicted, 3 fits running (26 of 100, 26.0 %, predicted P10-P90 10.0-20.0 %)" in up.summary
    assert down.severity == SEVERITY_INFO and "cleared" in down.summary and not m.standing


def test_windows_on_alternating_sides_never_raise_and_states_run_apart():
    """Below, above, below, above: never three running on one side. Wet below three times while dry
    stays inside: only wet is raised, with P10 as its threshold."""
    m = _manager()
    assert not _fits(m, [("dry", 50, 2), ("dry", 50, 15), ("dry", 50, 1), ("dry", 50, 16)])
    events = []
    for week in range(1, 4):
        events += m.on_squeal_fit(week * WEEK, [("dry", 80, 12, *BAND), ("wet", 80, 2, *BAND)])
    assert [(e.key, e.active, e.threshold) for e in events] == [("wet", True, 0.10)]
    assert "less than predicted" in events[0].summary


def test_small_windows_are_not_judged_and_leave_the_run_as_it_was():
    """Windows of fewer than squeal_drift_min_passes passes neither count towards a run nor clear
    it: above, (a window of 29 passes inside), above, above raises; a state without a prediction
    (NaN, as a message of a state without passes carries) is passed over too."""
    m = _manager(squeal_drift_min_passes=30)
    events = _fits(m, [("dry", 100, 30), ("dry", 29, 4), ("dry", 100, 30), ("dry", 100, 30)])
    assert [(e.stamp_ns // WEEK, e.active) for e in events] == [(4, True)]
    assert not m.on_squeal_fit(5 * WEEK, [("dry", 100, 15, float("nan"), float("nan"))])
    assert m.standing


def test_retuned_windows_apply_to_the_runs_so_far():
    """alerts.squeal_drift_windows set to 1 on a running manager: the next window outside raises."""
    m = _manager()
    assert not _fits(m, [("dry", 100, 30)])
    m.retune(alert_config({"alerts.squeal_drift_windows": 1}, lead_time_days=60.0))
    assert [e.active for e in m.on_squeal_fit(2 * WEEK, [("dry", 100, 35, *BAND)])] == [True]
