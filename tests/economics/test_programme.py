"""The network grinding programme (economics.programme): its schedules' costs by a second path, its
optimum against exhaustive search, its capacity, budget and risk limit, and its realised cost on a
network whose truth is known, against grinding on a fixed cycle and when due."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import stats

from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.economics import baselines
from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.economics.programme import (
    Z90,
    Law,
    Rules,
    months_of,
    plan,
    schedule_terms,
    schedules,
    visit_risks,
)
from rail_monitor.simulation.network import network_outlooks, true_days


def _outlook(i: int, due: float, cycle: float, sd: float, cost: float = 500.0, late: float = 1500.0,
             newest_days: float = 0.0) -> SiteOutlook:
    spread = np.exp(sd * Z90 * np.array([-1.0, 0.0, 1.0]))
    return SiteOutlook(f"s{i}", int(newest_days * NS_PER_DAY), due * spread, cycle * spread, cost, late, 500.0)


def test_the_law_passes_through_the_forecast_quantiles():
    """Against scipy.stats.lognorm: the law's chances at P10, P50 and P90 are 0.1, 0.5, 0.9 to 1e-12,
    and its CDF is lognorm's; a forecast of never is never."""
    law = Law.through(np.array([120.0, 300.0, 750.0]))
    ref = stats.lognorm(s=law.sigma, scale=np.exp(law.mu))
    np.testing.assert_allclose(law.before(np.array([120.0, 300.0, 750.0])), [0.1, 0.5, 0.9], atol=1e-12)
    days = np.geomspace(10, 5000, 30)
    np.testing.assert_allclose(law.before(days), ref.cdf(days), rtol=1e-12, atol=1e-300)
    assert Law.through(np.array([np.inf] * 3)).before(1e9) == 0.0


def test_every_schedule_costs_what_its_visits_cost():
    """The vectorised candidates (schedules) against each one's months costed gap by gap (visit_risks,
    schedule_terms), to 1e-9 relative; a site already past due and one that never is, too."""
    rules = Rules(36, 40 * NS_PER_DAY)
    for o in (_outlook(0, 200.0, 300.0, 0.3), _outlook(1, 10.0, 150.0, 0.5), _outlook(2, np.inf, np.inf, 0.3)):
        s = schedules(o, rules)
        for k in range(len(s.cost)):
            risks = visit_risks(o, rules, months_of(int(s.first[k]), int(s.gap[k]), rules.months))
            expected, charged = schedule_terms(o, risks, rules)
            assert s.expected[k] == pytest.approx(expected, rel=1e-9) and s.cost[k] == pytest.approx(charged, rel=1e-9)
            assert s.risk[k] == pytest.approx(risks.max(), rel=1e-9) and s.lates[k] == pytest.approx(risks.sum(),
                                                                                                     rel=1e-9)


def test_the_optimum_equals_exhaustive_search():
    """Three sites, one visit a month: the MILP's cost equals the least over every combination of
    their candidate schedules that keeps the capacity (searched by brute force)."""
    sites = [_outlook(0, 60.0, 120.0, 0.25), _outlook(1, 70.0, 150.0, 0.3), _outlook(2, 65.0, 200.0, 0.2)]
    rules = Rules(8, 0, capacity=1)
    cands = [schedules(o, rules) for o in sites]
    best = np.inf
    for pick in itertools.product(*(range(len(c.cost)) for c in cands)):
        months = np.concatenate([months_of(int(c.first[k]), int(c.gap[k]), 8)
                                 for c, k in zip(cands, pick, strict=True)])
        if len(months) and np.bincount(months).max() > 1:
            continue
        best = min(best, sum(c.cost[k] for c, k in zip(cands, pick, strict=True)))
    prog = plan(sites, rules)
    charged = sum(schedule_terms(o, visit_risks(o, rules, v), rules)[1]
                  for o, v in zip(sites, prog.visits, strict=True))
    assert charged == pytest.approx(best, rel=1e-9)
    assert np.bincount(np.concatenate(prog.visits)).max() <= 1


def test_capacity_budget_and_risk_limit_hold():
    """60 sites over 5 years: no month over its capacity, no year over its budget, every gap's risk at
    most the limit (capacity and budget leave room for it), and the limit costs more than none."""
    sites = network_outlooks(60, 3)
    free = plan(sites, Rules(60, 0))
    peak = np.bincount(np.concatenate(free.visits)).max()
    assert free.risk.max() <= 0.1 + 1e-12
    rules = Rules(60, 0, capacity=peak - 2, budget_per_year=0.95 * _yearly(free).max())
    held = plan(sites, rules)
    assert np.bincount(np.concatenate(held.visits)).max() <= rules.capacity
    assert _yearly(held).max() <= rules.budget_per_year + 1e-6
    assert held.risk.max() <= 0.1 + 1e-12
    loose = plan(sites, Rules(60, 0, risk_limit=0.5))
    assert loose.expected_cost.sum() < free.expected_cost.sum()


def _yearly(prog) -> np.ndarray:
    return np.bincount(np.concatenate(prog.visits) // 12, minlength=5) * 500.0


def test_on_a_network_of_known_truth_the_programme_costs_least():
    """80 sites whose true days to threshold now and per cycle are drawn from their forecasts (one draw
    of K_b's error per site: its due date and its cycle move together), simulated forward: the
    programme's realised cost is below a fixed cycle's (the network's median cycle) and below grinding
    at each forecast's median, and at most 10 % of its visits (+3 binomial s.d.) come after the
    threshold, against about half when grinding at the median."""
    sites = network_outlooks(80, 11)
    rules = Rules(60, 0)
    due, cyc = true_days(sites, 5)
    every = baselines.median_cycle_months(sites, rules)
    runs = {"programme": plan(sites, rules).visits, "fixed": baselines.fixed_cycle(sites, rules, every),
            "due": baselines.when_due(sites, rules)}
    out = {}
    for name, visits in runs.items():
        res = [baselines.realised(o, rules, v, d, c) for o, v, d, c in zip(sites, visits, due, cyc, strict=True)]
        out[name] = (sum(r[0] for r in res), sum(r[1] for r in res), sum(len(v) for v in visits))
    print({k: (round(c), late, n) for k, (c, late, n) in out.items()})
    assert out["programme"][0] < out["fixed"][0] and out["programme"][0] < out["due"][0]
    _, late, n = out["programme"]
    assert late / n <= 0.1 + 3 * np.sqrt(0.1 * 0.9 / n)
    assert out["due"][1] / out["due"][2] > 0.3
