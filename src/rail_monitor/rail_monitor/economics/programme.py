"""A grinding programme for a network of sites: the months in which to visit each site over a
horizon, at least expected cost, with each site's risk of a band passing its threshold before
its visit held to a limit, within a capacity of visits per month and a budget per year.

Each site's forecast (economics.outlook) gives the days to its threshold now and after a grind,
as P10/P50/P90; each is taken as log-normal through them (median P50, ln-spread from P10-P90).
A site's candidate schedules are no visit, or a first visit in a month from ``pull_forward``
months before its due date's EARLIEST quantile up to its quantile max(GAP_RISKS), then repeat
visits at a gap of one of the cycle's GAP_RISKS quantiles. A gap's risk is the chance the
threshold comes first; a visit costs its preventive cost plus that risk times the corrective
visit's extra; the span from the last visit to the horizon adds its risk times a corrective visit
(one is then owed). The time a rail spends past its threshold before its visit (or the horizon)
owes one more corrective visit per median cycle of it (OVERDUE_UNIT): left corrugated, the rail
roughens on, a cycle's growth in each cycle's time, and so leaving an overdue site unvisited, or
visiting it late, is never free. A gap whose risk is above the limit is charged OVER_LIMIT corrective visits,
and RISK_WEIGHT more per unit of excess, so the limit holds wherever capacity and budget allow it
and the problem is never infeasible. Choosing one schedule per site is a set partition, solved by
scipy.optimize.milp (HiGHS branch and cut, to a 1 % gap): already a dependency, and its LP
relaxation of a partition with few capacity rows is nearly integral, so 500 sites solve in
seconds (bench.plan). Gaps are treated as independent draws of the cycle
(docs/models.md, "Grinding economics and a programme for a network").
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import optimize, sparse, special

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.economics.outlook import DAYS_PER_YEAR, SiteOutlook

MONTH_DAYS = DAYS_PER_YEAR / 12
Z90 = float(special.ndtri(0.9))
GAP_RISKS = (0.01, 0.03, 0.1, 0.2, 0.3, 0.5, 0.7)  # a schedule's repeat gaps: these quantiles of the cycle
EARLIEST = 0.001                     # quantile of the due date from which pull_forward counts
RISK_WEIGHT = 1.0e3                  # late visits charged per unit of risk above the limit
OVER_LIMIT = 10.0                    # and per gap above it at all: the limit holds where it can
SHORTEST_DAYS = 1e-3                 # a forecast of 0 days (due now), as a log-normal


@dataclass(frozen=True)
class Rules:
    """What a programme must respect."""

    months: int                      # horizon [month of MONTH_DAYS]
    start_ns: int                    # start of the first month [ns]
    capacity: int = 0                # most visits in a month (0: no limit)
    budget_per_year: float = 0.0     # most preventive visit cost per programme year (0: no limit) [cost unit]
    risk_limit: float = 0.1          # most chance a band passes its threshold before its visit [-]
    pull_forward: int = 6            # months a first visit may come before the due date's 0.1 % quantile

    @classmethod
    def over(cls, years: float, start_ns: int, capacity: int = 0, budget_per_year: float = 0.0,
             risk_limit: float = 0.1, pull_forward: int = 6) -> Rules:
        """The rules of a horizon of years [year] (whole months, at least one)."""
        return cls(max(1, round(12 * years)), start_ns, capacity, budget_per_year, risk_limit, pull_forward)

    def month_ns(self, m: float) -> int:
        """When programme month m begins [ns]."""
        return int(self.start_ns + m * MONTH_DAYS * NS_PER_DAY)


@dataclass(frozen=True)
class Law:
    """A log-normal time to threshold [day] (mu = inf: never)."""

    mu: float
    sigma: float

    @classmethod
    def through(cls, q: np.ndarray) -> Law:
        """Through a forecast's P10, P50, P90 [day]."""
        q = np.maximum(np.asarray(q, float), SHORTEST_DAYS)
        if not np.isfinite(q[1]):
            return cls(np.inf, 1.0)
        hi = q[2] if np.isfinite(q[2]) else q[1] * q[1] / q[0]
        return cls(float(np.log(q[1])), max(float(np.log(hi / q[0])) / (2 * Z90), 1e-6))

    def before(self, days: np.ndarray | float) -> np.ndarray:
        """Chance the threshold comes within days [-]."""
        days = np.maximum(np.asarray(days, float), 0.0)
        with np.errstate(divide="ignore"):
            return special.ndtr((np.log(days) - self.mu) / self.sigma)

    def past(self, days: np.ndarray | float) -> np.ndarray:
        """Expected days past the threshold within days, E[(days - T)+] [day] (0 where it never comes):
        days*Phi(z) - exp(mu + sigma^2/2)*Phi(z - sigma), z = (ln days - mu)/sigma, the log-normal's
        partial expectation."""
        days = np.maximum(np.asarray(days, float), 0.0)
        if not np.isfinite(self.mu):
            return np.zeros_like(days)
        with np.errstate(divide="ignore"):
            z = (np.log(days) - self.mu) / self.sigma
        return np.maximum(days * special.ndtr(z) - np.exp(self.mu + self.sigma ** 2 / 2) * special.ndtr(z - self.sigma),
                          0.0)

    def quantile(self, p: float) -> float:
        return float(np.exp(self.mu + self.sigma * special.ndtri(p)))


@dataclass(frozen=True)
class Schedules:
    """One site's candidate schedules (C of them): cost, visits and risks, as the MILP takes them."""

    cost: np.ndarray          # expected cost with the excess-risk charge (C,) [cost unit]
    expected: np.ndarray      # expected cost without it (C,)
    risk: np.ndarray          # largest risk of a gap (C,) [-]
    lates: np.ndarray         # expected number of thresholds passed before a visit or the horizon (C,)
    first: np.ndarray         # first visit's month (C,) (-1: none)
    gap: np.ndarray           # months between visits (C,) (0: one visit, or none)
    option: np.ndarray        # index into the site's choices() (C,)


@dataclass(frozen=True)
class Programme:
    """The chosen schedule of every site (units as in Schedules), and the solve."""

    sites: list[str]
    visits: list[np.ndarray]        # months of each site's visits
    option: list[str]               # the option each site runs from its first visit
    expected_cost: np.ndarray       # per site [cost unit]
    risk: np.ndarray                # per site: largest gap risk [-]
    lates: np.ndarray               # per site: expected thresholds passed first [-]
    status: str                     # the solver's message
    seconds: float
    schedules: int                  # candidates the solver chose among


def offset_days(o: SiteOutlook, rules: Rules) -> float:
    """Days from the site's newest pass to the programme's start (the forecast's clock runs on)."""
    return (rules.start_ns - o.newest_ns) / NS_PER_DAY


def _gaps(o: SiteOutlook, rules: Rules, visits: np.ndarray) -> tuple[Law, Law, float, np.ndarray]:
    """A schedule's laws (due date, cycle), the days from the newest pass to the start, and its gaps'
    ends [day from the start]: to each visit in turn, then from the last to the horizon."""
    return (Law.through(o.due_days), Law.through(o.cycle_days), offset_days(o, rules),
            np.append(np.asarray(visits, float), rules.months) * MONTH_DAYS)


def visit_risks(o: SiteOutlook, rules: Rules, visits: np.ndarray) -> np.ndarray:
    """Risk of each gap of a schedule: to each visit in turn, then from the last to the horizon [-]."""
    due, cycle, shift, ends = _gaps(o, rules, visits)
    risks = cycle.before(np.diff(ends, prepend=0.0))
    risks[0] = due.before(shift + ends[0])
    return risks


def overdue_unit(cycle_days: np.ndarray) -> float:
    """Days past the threshold that owe one more corrective visit: the cycle's median [day]."""
    return max(float(cycle_days[1]), SHORTEST_DAYS)


def visit_overdue(o: SiteOutlook, rules: Rules, visits: np.ndarray) -> np.ndarray:
    """Expected time past the threshold in each gap of a schedule, within the horizon, in units of
    overdue_unit (the corrective visits it owes beyond the first) [-]."""
    due, cycle, shift, ends = _gaps(o, rules, visits)
    past = cycle.past(np.diff(ends, prepend=0.0))
    past[0] = due.past(shift + ends[0]) - due.past(max(shift, 0.0))  # before the start: no schedule's doing
    return past / overdue_unit(o.cycle_days)


def first_month(visits: np.ndarray) -> int:
    """A schedule's first visit's month (-1: no visit)."""
    return int(visits[0]) if len(visits) else -1


def schedule_terms(o: SiteOutlook, risks: np.ndarray, overdue: np.ndarray, rules: Rules,
                   first: int = -1) -> tuple[float, float]:
    """(expected cost, cost with the excess-risk charge) of a schedule from its gap risks and time
    past the threshold (visit_risks, visit_overdue), with the running cost of the outlook's option
    from its first visit's month (-1: none)."""
    extra = o.late_visit_cost - o.visit_cost
    expected = ((len(risks) - 1) * o.visit_cost + float(risks[:-1].sum()) * extra + float(risks[-1]) * o.late_visit_cost
                + float(overdue.sum()) * o.late_visit_cost + o.running_cost(first, rules.months))
    excess = float(np.maximum(risks - rules.risk_limit, 0.0).sum())
    over = int((risks > rules.risk_limit).sum())
    return expected, expected + o.late_visit_cost * (RISK_WEIGHT * excess + OVER_LIMIT * over)


def schedules(o: SiteOutlook, rules: Rules) -> Schedules:
    """The site's candidate schedules (see the module's docstring) under each of its options in
    turn, vectorised over first months; the first is no visit at all. Each equals schedule_terms
    over visit_risks and visit_overdue of its months, with the outlook under its option
    (SiteOutlook.under)."""
    due, shift, m = Law.through(o.due_days), offset_days(o, rules), rules.months
    first, gap, option = [np.array([-1])], [np.array([0])], [np.array([0])]
    before_start = due.past(max(shift, 0.0))
    visits, risks = [np.zeros(1)], [np.array([[0.0], [0.0], [due.before(shift + m * MONTH_DAYS)], [0.0]])]
    unit = overdue_unit(o.choices()[0].cycle_days)  # no visit: reckoned under the first choice
    overdue = [np.array([(due.past(shift + m * MONTH_DAYS) - before_start) / unit])]
    running = [np.zeros(1)]
    if np.isfinite(due.mu):
        lo = max(0, int((due.quantile(EARLIEST) - shift) // MONTH_DAYS) - rules.pull_forward)
        hi = min(m - 1, max(0, int(np.ceil((due.quantile(max(GAP_RISKS)) - shift) / MONTH_DAYS))))
        firsts = np.arange(min(lo, hi), hi + 1)
        p_first = due.before(shift + firsts * MONTH_DAYS)
        past_first = due.past(shift + firsts * MONTH_DAYS) - before_start
        for j, choice in enumerate(o.choices()):
            cycle, unit = Law.through(choice.cycle_days), overdue_unit(choice.cycle_days)
            gaps = {max(1, int(cycle.quantile(r) // MONTH_DAYS)) for r in GAP_RISKS} if np.isfinite(cycle.mu) else set()
            for g in sorted(gaps | {m}):       # a gap of m months: a single visit
                n = 1 + (m - 1 - firsts) // g
                tail = cycle.before((m - firsts - (n - 1) * g) * MONTH_DAYS)
                p_gap = np.where(n > 1, cycle.before(g * MONTH_DAYS), 0.0)
                overdue.append((past_first + (n - 1) * cycle.past(g * MONTH_DAYS)
                                + cycle.past((m - firsts - (n - 1) * g) * MONTH_DAYS)) / unit)
                first.append(firsts)
                gap.append(np.full(len(firsts), g if g < m else 0))
                option.append(np.full(len(firsts), j))
                visits.append(n)
                running.append(choice.cost_per_year * (m - firsts) / 12)
                # rows: first gap's risk, a repeat gap's, the tail's, and the repeats (a block is (4, C))
                risks.append(np.stack([p_first, p_gap, tail, n - 1]))
    extra, limit = o.late_visit_cost - o.visit_cost, rules.risk_limit
    p_first, p_gap, tail, repeats = (np.concatenate(row) for row in zip(*risks, strict=True))
    n = np.concatenate(visits)
    lates = p_first + repeats * p_gap + tail
    excess = (np.maximum(p_first - limit, 0) + repeats * np.maximum(p_gap - limit, 0)
              + np.maximum(tail - limit, 0))
    over = (p_first > limit) + repeats * (p_gap > limit) + (tail > limit)
    expected = (n * o.visit_cost + (p_first + repeats * p_gap) * extra + tail * o.late_visit_cost
                + np.concatenate(overdue) * o.late_visit_cost + np.concatenate(running))
    risk = np.maximum(np.maximum(p_first, tail), p_gap)
    charged = expected + o.late_visit_cost * (RISK_WEIGHT * excess + OVER_LIMIT * over)
    return Schedules(charged, expected, risk, lates, np.concatenate(first), np.concatenate(gap),
                     np.concatenate(option))


def months_of(first: int, gap: int, months: int) -> np.ndarray:
    """The visit months of a schedule."""
    if first < 0:
        return np.zeros(0, int)
    return np.arange(first, months, gap) if gap else np.array([first])


def plan(outlooks: Sequence[SiteOutlook], rules: Rules, time_limit_s: float = 60.0) -> Programme:
    """The programme of least expected cost (module docstring) over the sites' candidate schedules."""
    t0 = time.monotonic()
    per_site = [schedules(o, rules) for o in outlooks]
    sizes = np.array([len(s.cost) for s in per_site])
    col_site = np.repeat(np.arange(len(outlooks)), sizes)
    first = np.concatenate([s.first for s in per_site])
    gap = np.concatenate([s.gap for s in per_site])
    n = len(first)
    rows, cols, vals = [col_site], [np.arange(n)], [np.ones(n)]
    lb, ub = [np.ones(len(outlooks))], [np.ones(len(outlooks))]
    visit_cols = [(c, months_of(int(first[c]), int(gap[c]), rules.months)) for c in np.flatnonzero(first >= 0)]
    vc = np.concatenate([np.full(len(v), c) for c, v in visit_cols]) if visit_cols else np.zeros(0, int)
    vm = np.concatenate([v for _, v in visit_cols]) if visit_cols else np.zeros(0, int)
    base = len(outlooks)
    if rules.capacity:
        rows.append(base + vm)
        cols.append(vc)
        vals.append(np.ones(len(vm)))
        lb.append(np.zeros(rules.months))
        ub.append(np.full(rules.months, float(rules.capacity)))
        base += rules.months
    if rules.budget_per_year:
        years = (rules.months + 11) // 12
        rows.append(base + vm // 12)
        cols.append(vc)
        vals.append(np.array([outlooks[col_site[c]].visit_cost for c in vc]))
        lb.append(np.zeros(years))
        ub.append(np.full(years, rules.budget_per_year))
        base += years
    a = sparse.csr_array((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(base, n))
    res = optimize.milp(np.concatenate([s.cost for s in per_site]), integrality=np.ones(n),
                        bounds=optimize.Bounds(0, 1),
                        constraints=optimize.LinearConstraint(a, np.concatenate(lb), np.concatenate(ub)),
                        options={"time_limit": time_limit_s, "mip_rel_gap": 1e-2})
    if res.x is None:
        raise RailMonitorError(f"the grinding programme found no solution within {time_limit_s:g} s: {res.message}")
    chosen = np.flatnonzero(res.x > 0.5)
    pick = chosen[np.argsort(col_site[chosen])]
    local = pick - np.concatenate([[0], np.cumsum(sizes)[:-1]])
    option = np.concatenate([s.option for s in per_site])
    return Programme([o.site_id for o in outlooks],
                     [months_of(int(first[c]), int(gap[c]), rules.months) for c in pick],
                     [o.choices()[option[c]].name for o, c in zip(outlooks, pick, strict=True)],
                     np.array([s.expected[i] for s, i in zip(per_site, local, strict=True)]),
                     np.array([s.risk[i] for s, i in zip(per_site, local, strict=True)]),
                     np.array([s.lates[i] for s, i in zip(per_site, local, strict=True)]),
                     str(res.message), time.monotonic() - t0, n)
