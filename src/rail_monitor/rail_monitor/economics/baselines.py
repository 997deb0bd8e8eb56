"""What a programme is measured against: grinding every site on a fixed cycle, and grinding each
site when its forecast's median says; and what a schedule costs when the truth is known."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.economics.programme import (
    MONTH_DAYS,
    Law,
    Programme,
    Rules,
    first_month,
    offset_days,
    overdue_unit,
    schedule_terms,
    visit_overdue,
    visit_risks,
)


def fixed_cycle(outlooks: Sequence[SiteOutlook], rules: Rules, every: int) -> list[np.ndarray]:
    """Every site visited each ``every`` months whatever its forecast, the sites' phases spread
    over the cycle (site i first in month i mod every) as a grinding train's round would."""
    return [np.arange(i % every, rules.months, every) for i in range(len(outlooks))]


def median_cycle_months(outlooks: Sequence[SiteOutlook], rules: Rules) -> int:
    """The fixed cycle a network without forecasts would run: the median of the sites' cycle
    medians, in whole months (at least one; the horizon where no site ever needs grinding)."""
    cycles = [c for c in (Law.through(o.cycle_days).quantile(0.5) for o in outlooks) if np.isfinite(c)]
    return max(1, round(float(np.median(cycles)) / MONTH_DAYS)) if cycles else rules.months


def when_due(outlooks: Sequence[SiteOutlook], rules: Rules) -> list[np.ndarray]:
    """Each site visited in the month of its due date's median, then at its cycle's median, with
    no capacity or budget (months rounded to the nearest, at least one apart)."""
    out = []
    for o in outlooks:
        due, cycle = Law.through(o.due_days), Law.through(o.cycle_days)
        if not np.isfinite(due.mu):
            out.append(np.zeros(0, int))
            continue
        first = max(0, round((due.quantile(0.5) - offset_days(o, rules)) / MONTH_DAYS))
        step = max(1, round(cycle.quantile(0.5) / MONTH_DAYS)) if np.isfinite(cycle.mu) else rules.months
        out.append(np.arange(first, rules.months, step))
    return out


def expected(outlooks: Sequence[SiteOutlook], rules: Rules, visits: Sequence[np.ndarray]) -> tuple[np.ndarray, ...]:
    """Per site: (expected cost, largest gap risk, expected thresholds passed first) of schedules, each
    outlook under the option its schedule runs (SiteOutlook.under)."""
    rows = []
    for o, v in zip(outlooks, visits, strict=True):
        risks = visit_risks(o, rules, v)
        cost = schedule_terms(o, risks, visit_overdue(o, rules, v), rules, first_month(v))[0]
        rows.append((cost, risks.max(), risks.sum()))
    return tuple(np.array(c) for c in zip(*rows, strict=True)) if rows else (np.zeros(0),) * 3


def realised(o: SiteOutlook, rules: Rules, visits: np.ndarray, due_days: float,
             cycle_days: float | Sequence[float]) -> tuple[float, int]:
    """(cost, thresholds passed first) of a schedule on a site whose true days to threshold now
    and after each grind are known (one cycle, or one per grind in turn, repeated): a visit after
    the threshold is corrective; a threshold passed between the last visit and the horizon owes a
    corrective visit, and the time past a threshold one more per overdue_unit of it, as in the plan."""
    cycles = np.atleast_1d(np.asarray(cycle_days, float))
    cross = due_days - offset_days(o, rules)       # days from the start
    unit = overdue_unit(o.cycle_days)  # time past the threshold before the start (cross < 0) is no schedule's doing
    cost, late = 0.0, 0
    for k, m in enumerate(np.asarray(visits, float) * MONTH_DAYS):
        passed = m >= cross
        cost += o.late_visit_cost * (1.0 + (m - max(cross, 0.0)) / unit) if passed else o.visit_cost
        late += int(passed)
        cross = m + cycles[k % len(cycles)]
    end = rules.months * MONTH_DAYS
    if end > cross:
        cost += o.late_visit_cost * (1.0 + (end - max(cross, 0.0)) / unit)
        late += 1
    return cost, late


@dataclass(frozen=True)
class Priced:
    """A way of running the network over the horizon, priced on the forecasts."""

    name: str
    visits: list[np.ndarray]   # months of each site's visits
    cost: float                # expected cost [cost unit]
    lates: float               # expected thresholds passed before a visit (or owed at the horizon) [-]

    @property
    def count(self) -> int:
        return sum(len(v) for v in self.visits)


def priced(outlooks: Sequence[SiteOutlook], rules: Rules, prog: Programme, every: int) -> list[Priced]:
    """The programme (each site under its chosen option), a fixed cycle of ``every`` months and
    grinding when due (both grinding only), each at its expected cost."""
    grinding = [o.under("grind") for o in outlooks]
    runs = [("programme", [o.under(c) for o, c in zip(outlooks, prog.option, strict=True)], prog.visits),
            (f"fixed {every}-month cycle", grinding, fixed_cycle(outlooks, rules, every)),
            ("when due (forecast median)", grinding, when_due(outlooks, rules))]
    out = []
    for name, under, visits in runs:
        cost, _, lates = expected(under, rules, visits)
        out.append(Priced(name, visits, float(cost.sum()), float(lates.sum())))
    return out
