"""A site's grinding outlook: when it is due, how long a grind lasts, and what a visit costs,
each with the forecast's uncertainty, and the options a programme may choose there; the input of
a network programme (economics.programme)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.forecast import MAX_DATED_DAYS
from rail_monitor.economics.config import EconomicsConfig

DAYS_PER_YEAR = 365.25
WIDE = 4.0  # a cycle's P90/P10 above which a forecast is too wide to plan cheaply (ln-spread over 0.54)


@dataclass(frozen=True)
class Option:
    """One way of running a site from its next visit: its grinding cycle P10, P50, P90 [day] with
    the option in force, its running cost [cost unit/year], and what else it changes (one line)."""

    name: str                  # economics.config.OPTIONS
    cycle_days: np.ndarray
    cost_per_year: float = 0.0
    effects: str = ""


@dataclass(frozen=True)
class SiteOutlook:
    """One site's outlook. Days are P10, P50 and P90 (inf: never at the present traffic)."""

    site_id: str
    newest_ns: int             # newest pass counted: the origin of due_days [ns]
    due_days: np.ndarray       # from newest_ns until the first band reaches its threshold [day]
    cycle_days: np.ndarray     # from a grind now until the first band reaches its threshold [day]
    visit_cost: float          # a preventive visit [cost unit]
    late_visit_cost: float     # a corrective visit, after a band passed its threshold [cost unit]
    length_m: float            # ground per visit [m]
    options: tuple[Option, ...] = ()  # what a programme may choose (none given: grinding on the forecast)

    @property
    def due_day(self) -> float:
        """The median due date in days since the epoch: the key of 'due first' [day]."""
        return self.newest_ns / NS_PER_DAY + float(self.due_days[1])

    @property
    def wide(self) -> bool:
        """Whether the cycle's P90 is over WIDE times its P10: holding a risk limit there takes visits
        far more often than the median needs, and a roughness survey would pay."""
        return bool(self.cycle_days[2] > WIDE * self.cycle_days[0])

    def due_ns(self) -> np.ndarray:
        """The due date's P10, P50, P90 [ns] (0: never, or past the forecast's dated horizon)."""
        return np.array([self.newest_ns + int(d * NS_PER_DAY) if d <= MAX_DATED_DAYS else 0
                         for d in self.due_days.tolist()], np.int64)

    def problem(self) -> str:
        """Why a programme cannot be planned on this outlook ('' if it can): days must be ordered
        quantiles, none negative or NaN (inf: never); costs finite, none negative, a corrective visit
        not cheaper than a preventive one."""
        days = [self.due_days, self.cycle_days, *(o.cycle_days for o in self.options)]
        if any(np.shape(d) != (3,) or np.isnan(d).any() or (d < 0).any() or (d[1:] < d[:-1]).any() for d in days):
            return "its days are not three ordered quantiles of 0 or more"
        costs = np.array([self.visit_cost, self.late_visit_cost, self.length_m,
                          *(o.cost_per_year for o in self.options)])
        if not np.isfinite(costs).all() or (costs < 0).any() or self.late_visit_cost < self.visit_cost:
            return "its costs are not finite and 0 or more, a corrective visit at least a preventive one"
        return ""

    def choices(self) -> tuple[Option, ...]:
        """The options a programme may choose here."""
        return self.options or (Option("grind", self.cycle_days),)

    def under(self, name: str) -> SiteOutlook:
        """The outlook with one option in force (its cycle, and no other choice); grind is always
        there: it is what a fixed cycle or grinding when due runs."""
        if name == "grind":
            return replace(self, options=())
        option = next((o for o in self.choices() if o.name == name), None)
        if option is None:
            raise ValueError(f"site {self.site_id} does not offer {name}")
        return replace(self, cycle_days=option.cycle_days, options=(option,))

    def running_cost(self, first_month: int, months: int) -> float:
        """The chosen option's running cost from the first visit's month to the horizon [cost unit]
        (the outlook under one option; none before any visit)."""
        if first_month < 0 or len(self.choices()) != 1:
            return 0.0
        return self.choices()[0].cost_per_year * (months - first_month) / 12

    def cost_per_year(self) -> np.ndarray:
        """Preventive grinding's cost per year on the cycle, P10, P50, P90 [cost unit/year] (the
        short cycle is the costly one: P10 of the cost is at P90 of the cycle)."""
        with np.errstate(divide="ignore"):
            return self.visit_cost * DAYS_PER_YEAR / self.cycle_days[::-1]


def site_outlook(est: CorrugationEstimator, cfg: EconomicsConfig, options: tuple[Option, ...] = ()) -> SiteOutlook:
    """The outlook of a site's state (after its history, or resumed from its checkpoint): the
    forecast's P10/P50/P90 now and after a grind now (CorrugationEstimator.forecast_interval), the
    visits' costs, and the options priced for it (economics.options.site_options)."""
    return SiteOutlook(est.site.site_id, int(est.newest_ns), est.forecast_interval().days.astype(float),
                       est.forecast_interval(after_grinding=True).days.astype(float), cfg.visit(),
                       cfg.visit(late=True), cfg.grind_length_m, options)
