"""A site's grinding outlook: when it is due, how long a grind lasts, and what a visit costs,
each with the forecast's uncertainty; the input of a network programme (economics.programme)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.economics.config import EconomicsConfig

DAYS_PER_YEAR = 365.25


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

    def cost_per_year(self) -> np.ndarray:
        """Preventive grinding's cost per year on the cycle, P10, P50, P90 [cost unit/year] (the
        short cycle is the costly one: P10 of the cost is at P90 of the cycle)."""
        with np.errstate(divide="ignore"):
            return self.visit_cost * DAYS_PER_YEAR / self.cycle_days[::-1]


def site_outlook(est: CorrugationEstimator, cfg: EconomicsConfig) -> SiteOutlook:
    """The outlook of a site's state (after its history, or resumed from its checkpoint): the
    forecast's P10/P50/P90 now and after a grind now (CorrugationEstimator.forecast_interval), and
    the visits' costs."""
    return SiteOutlook(est.site.site_id, int(est.newest_ns), est.forecast_interval().days.astype(float),
                       est.forecast_interval(after_grinding=True).days.astype(float), cfg.visit(),
                       cfg.visit(late=True), cfg.grind_length_m)
