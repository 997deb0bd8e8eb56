"""The network grinding programme (economics.programme): its schedules' costs by a second path, its
optimum against exhaustive search, its capacity, budget and risk limit, and its realised cost on a
network whose truth is known, against grinding on a fixed cycle and when due."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest
from scipy import stats

from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.economics import baselines
from rail_monitor.economics.outlook import Option, SiteOutlook
from rail_monitor.economics.programme import (
    Z90,
    Law,
    Rules,
    first_month,
    months_of,
    plan,
    schedule_terms,
    schedules,
    visit_overdue,
    visit_risks,
)
from rail_monitor.simulation.network import network_outlooks, true_days


def _outlook(i: int, due: float, cycle: float, sd: float, cost: float = 500.0, late: float = 1500.0,
             newest_days: float = 0.0) -> SiteOutlook:
    spread = np.exp(sd * Z90 * np.array([-1.0, 0.0, 1.0]))
    return SiteOutlook(f"s{i}", int(newest_days * NS_PER_DAY), due * spread, cycle * spread, cost, late, 500.0)


def _with_options(o: SiteOutlook, speed_cost: float, applicator_cost: float) -> SiteOutlook:
    """The site with speed control (cycle x1.4) and a friction modifier (x2.5, twice the ln-spread) offered."""
    law = Law.through(o.cycle_days)
    wide = np.exp(np.log(2.5 * o.cycle_days[1]) + 2 * law.sigma * Z90 * np.array([-1.0, 0.0, 1.0]))
    return replace(o, options=(Option("grind", o.cycle_days), Option("speed_control", 1.4 * o.cycle_days, speed_cost),
                               Option("friction_modifier", wide, applicator_cost)))


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
    visit_overdue, schedule_terms), to 1e-9 relative; a site already past due and one that never is, too."""
    rules = Rules(36, 40 * NS_PER_DAY)
    for o in (_outlook(0, 200.0, 300.0, 0.3), _outlook(1, 10.0, 150.0, 0.5), _outlook(2, np.inf, np.inf, 0.3),
              _with_options(_outlook(3, 200.0, 300.0, 0.3), 60.0, 400.0)):
        s = schedules(o, rules)
        assert set(s.option) == set(range(len(o.choices())))
        for k in range(len(s.cost)):
            under = o.under(o.choices()[s.option[k]].name)
            months = months_of(int(s.first[k]), int(s.gap[k]), rules.months)
            risks = visit_risks(under, rules, months)
            overdue = visit_overdue(under, rules, months)
            expected, charged = schedule_terms(under, risks, overdue, rules, int(s.first[k]))
            assert s.expected[k] == pytest.approx(expected, rel=1e-9) and s.cost[k] == pytest.approx(charged, rel=1e-9)
            assert s.risk[k] == pytest.approx(risks.max(), rel=1e-9) and s.lates[k] == pytest.approx(risks.sum(),
                                                                                                     rel=1e-9)


def test_the_optimum_equals_exhaustive_search():
    """Three sites, one visit a month: the MILP's cost equals the least over every combination of
    their candidate schedules that keeps the capacity (searched by brute force)."""
    sites = [_outlook(0, 60.0, 120.0, 0.25), _outlook(1, 70.0, 150.0, 0.3),
             _with_options(_outlook(2, 65.0, 200.0, 0.2), 30.0, 300.0)]
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
    charged = sum(_terms(o.under(c), rules, v)[1] for o, v, c in zip(sites, prog.visits, prog.option, strict=True))
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


def test_the_programme_takes_an_option_where_it_is_cheaper():
    """Two sites alike (due in 100 days, a 300-day cycle; 500 a preventive visit) offering a
    friction modifier that makes the cycle 2.5 times longer: at 100 a year (five years: 500, against
    about three visits saved) the programme takes it; at 2,000 a year it does not, and speed control
    (x1.4 at 60 a year) beats grinding alone. Each site's expected cost is its chosen schedule's,
    running cost included, and the pair costs less than grinding alone."""
    sites = [_with_options(_outlook(0, 100.0, 300.0, 0.2), 1e6, 100.0), _with_options(_outlook(1, 100.0, 300.0, 0.2),
                                                                                      60.0, 2000.0)]
    rules = Rules(60, 0)
    prog = plan(sites, rules)
    assert prog.option == ["friction_modifier", "speed_control"]
    for o, v, opt, cost in zip(sites, prog.visits, prog.option, prog.expected_cost, strict=True):
        assert cost == pytest.approx(_terms(o.under(opt), rules, v)[0], rel=1e-9)
    grind_only = plan([o.under("grind") for o in sites], rules)
    assert prog.expected_cost.sum() < grind_only.expected_cost.sum()


def _terms(o: SiteOutlook, rules: Rules, v: np.ndarray) -> tuple[float, float]:
    return schedule_terms(o, visit_risks(o, rules, v), visit_overdue(o, rules, v), rules, first_month(v))


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


def test_a_realised_schedule_takes_each_grinds_own_cycle():
    """Counted by hand (months of 30.44 days): due in 100 days, visits in months 2, 9 and 14 of 24.
    Cycles 300 then 100 days: on time (day 61), on time (274 < 361), late (426 >= 374), and the
    threshold passed again on day 726 before the horizon (730.5) owes one more: 2 on time, 2 late,
    each late one owing a further visit per median cycle (300 days) it came after the threshold (426 -
    374 and 730.5 - 726 days). One cycle of 300 days throughout: only the one owed at the end is late."""
    o, rules = _outlook(0, 100.0, 300.0, 0.2), Rules(24, 0)
    visits = np.array([2, 9, 14])
    m = 365.25 / 12
    cost, late = baselines.realised(o, rules, visits, 100.0, [300.0, 100.0])
    assert late == 2 and cost == pytest.approx(2 * 500.0 + 1500.0 * (2 + (14 * m - (9 * m + 100)) / 300.0
                                                                     + (24 * m - (14 * m + 300)) / 300.0), rel=1e-12)
    cost, late = baselines.realised(o, rules, visits, 100.0, 300.0)
    assert late == 1 and cost == pytest.approx(3 * 500.0 + 1500.0 * (1 + (24 * m - (14 * m + 300)) / 300.0), rel=1e-12)


def test_the_time_past_the_threshold_is_the_log_normal_s_partial_expectation():
    """Law.past(d) = E[(d - T)+] = the integral of the CDF from 0 to d, against scipy's quadrature of
    lognorm's CDF, to 1e-9 relative; 0 where the threshold never comes."""
    from scipy import integrate

    law = Law.through(np.array([120.0, 300.0, 750.0]))
    ref = stats.lognorm(s=law.sigma, scale=np.exp(law.mu))
    for d in (30.0, 300.0, 2000.0):
        want = integrate.quad(ref.cdf, 0.0, d, limit=200, epsabs=0, epsrel=1e-12)[0]
        assert float(law.past(d)) == pytest.approx(want, rel=1e-9)
    assert float(Law.through(np.array([np.inf] * 3)).past(1e6)) == 0.0


def test_a_site_past_its_threshold_is_visited_at_once():
    """A site certainly past its threshold (due 100 days before the programme starts, ln-sd 0.05; cycle
    150 days) beside one due in a year: the overdue site's first visit is in month 0, whatever the
    horizon, because every month it waits costs a fifth of a corrective visit. Without that charge
    (0.29.0) it was left unvisited over one year and five: one corrective visit owed at the horizon
    looked cheaper than a cycle of visits, every schedule's first gap being as late as no visit's."""
    sites = [_outlook(0, 60.0, 150.0, 0.05), _outlook(1, 365.0, 400.0, 0.2, newest_days=160.0)]
    for months in (12, 60):
        rules = Rules(months, 160 * NS_PER_DAY, capacity=1)
        prog = plan(sites, rules)
        assert int(prog.visits[0][0]) == 0 and len(prog.visits[0]) >= months * 30 // 150
        s = schedules(sites[0], rules)
        assert s.expected[0] > s.expected[np.argmin(s.cost)]  # no visit: the dearest to leave
