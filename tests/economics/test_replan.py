"""Re-planning a network on each site's newest outlook (rail_monitor.economics.replan): every re-plan
is the programme of the newest outlooks heard, whatever order the sites' outlooks arrive in; an
outlook older than its site's newest changes nothing; a grinding's outlook moves its site's first
visit later, and a survey that finds the rail rougher brings it forward."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.economics.programme import Rules, plan
from rail_monitor.economics.replan import Replanner, replay

DAY = 86_400 * 10**9
T0 = 1_700_000_000 * 10**9
CYCLE = np.array([300.0, 700.0, 1900.0])


def _outlook(site: str, day: int, due_p50: float) -> SiteOutlook:
    """An outlook made on day (its newest pass), due in due_p50 days with the spread of CYCLE."""
    return SiteOutlook(site, T0 + day * DAY, CYCLE / CYCLE[1] * due_p50, CYCLE, 500.0, 1500.0, 500.0)


def _network(seed: int) -> list[tuple[int, SiteOutlook]]:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(6):
        due = rng.uniform(100, 900)
        for k in range(4):  # a survey a month: the due date draws nearer as the rail roughens
            out.append((T0 + (30 * k + i) * DAY, _outlook(f"s{i}", 30 * k + i, due - 30 * k)))
    return out


def test_every_re_plan_is_the_programme_of_the_newest_outlooks_in_any_arrival_order():
    network = _network(3)
    replans = replay(network, Replanner(years=4.0, capacity=2))
    assert len(replans) == len(network)
    last = replans[-1]
    newest = {o.site_id: o for _, o in sorted(network, key=lambda x: x[0])}
    assert [o.site_id for o in last.outlooks] == [f"s{i}" for i in range(6)]
    assert all(a is newest[a.site_id] for a in last.outlooks)
    rules = Rules.over(4.0, max(o.newest_ns for o in newest.values()), capacity=2)
    assert last.rules == rules
    direct = plan(list(newest.values()), rules)
    # arrivals across sites in another order (each site's own in order): the same last programme
    rng = np.random.default_rng(5)
    shuffled = Replanner(years=4.0, capacity=2)
    order = rng.permutation(len(network))
    by_site: dict[str, list] = {}
    for stamp, o in network:
        by_site.setdefault(o.site_id, []).append((stamp, o))
    queue = [by_site[network[j][1].site_id].pop(0) for j in order]
    out = [r for stamp, o in queue if (r := shuffled.take(stamp, o)) is not None]
    for p in (last.programme, out[-1].programme):  # HiGHS's 1 % gap: each within it of the direct solve
        assert abs(p.expected_cost.sum() - direct.expected_cost.sum()) <= 0.01 * direct.expected_cost.sum() + 1e-9
        per_month = np.bincount(np.concatenate(p.visits).astype(int), minlength=rules.months)
        assert per_month.max() <= 2 and p.risk.max() <= rules.risk_limit + 1e-12


def test_an_outlook_older_than_its_site_s_newest_or_unplannable_changes_nothing():
    """An older outlook is passed over; one with NaN or unordered days, or a corrective visit cheaper
    than a preventive one, is refused in one line, and the next good one is planned on as before."""
    import pytest

    planner = Replanner(years=2.0)
    first = planner.take(T0 + 10 * DAY, _outlook("a", 10, 400.0))
    assert first is not None
    assert planner.take(T0 + 5 * DAY, _outlook("a", 5, 30.0)) is None
    assert planner.latest["a"][0] == T0 + 10 * DAY and planner.latest["a"][1].due_days[1] == 400.0
    bad = [replace(_outlook("a", 20, 300.0), due_days=np.array([np.nan, 1.0, 2.0])),
           replace(_outlook("b", 20, 300.0), cycle_days=np.array([300.0, 200.0, 900.0])),
           replace(_outlook("b", 20, 300.0), late_visit_cost=100.0)]
    for o in bad:
        with pytest.raises(ValueError, match="refused: its"):
            planner.take(T0 + 20 * DAY, o)
    assert list(planner.latest) == ["a"] and planner.latest["a"][0] == T0 + 10 * DAY
    again = planner.take(T0 + 30 * DAY, _outlook("b", 30, 200.0))
    assert [o.site_id for o in again.outlooks] == ["a", "b"]


def test_a_grinding_moves_its_site_s_visit_later_and_a_rough_survey_brings_it_forward():
    planner = Replanner(years=3.0)
    planner.take(T0, _outlook("b", 0, 500.0))
    due_soon = planner.take(T0 + DAY, _outlook("a", 1, 60.0)).programme
    ground = planner.take(T0 + 2 * DAY, _outlook("a", 2, CYCLE[1])).programme  # after a grind: due = the cycle
    rough = planner.take(T0 + 3 * DAY, _outlook("a", 3, 20.0)).programme
    first = {name: int(dict(zip(p.sites, p.visits, strict=True))["a"][0])
             for name, p in (("soon", due_soon), ("ground", ground), ("rough", rough))}
    assert first["ground"] > first["soon"] >= first["rough"]
