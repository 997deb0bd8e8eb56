"""A network's grinding programme re-planned as its sites' outlooks arrive: each site's engine makes
a new outlook whenever a survey, a grinding or an indirect roughness observation changes its state
(engine.corrugation_site), and the programme is solved again over the newest outlook of every site
heard so far (economics.programme.plan). The grinding_planner node runs it live on the outlooks'
topics; ``rail-monitor plan --replan`` runs it over the outlooks of the sites' histories, in stamp
order. The same outlooks in the same order give the same programmes.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.economics.programme import Programme, Rules, plan


@dataclass(frozen=True)
class Replan:
    """One re-plan: the outlook that made it (stamped with its event [ns]), the rules it was solved
    under, the outlooks it was solved over with their stamps (in the order first heard), and the
    programme."""

    stamp_ns: int
    site_id: str
    rules: Rules
    outlooks: list[SiteOutlook]
    stamps_ns: list[int]
    programme: Programme


@dataclass
class Replanner:
    """The newest outlook of each site, and the rules a re-plan uses: a horizon of years from the
    newest pass counted at any site, at most capacity visits a month, budget_per_year of preventive
    cost, each gap's risk held to risk_limit (economics.programme.Rules)."""

    years: float = 5.0
    capacity: int = 0
    budget_per_year: float = 0.0
    risk_limit: float = 0.1
    pull_forward: int = 6
    time_limit_s: float = 60.0
    latest: dict[str, tuple[int, SiteOutlook]] = field(default_factory=dict)

    def take(self, stamp_ns: int, outlook: SiteOutlook) -> Replan | None:
        """The programme re-planned with this outlook, made at stamp_ns [ns]; None where the site
        has a newer one already (an outlook that arrives late changes nothing). An outlook that
        cannot be planned on raises ValueError, and one whose solve fails re-raises; either leaves
        the newest outlooks as they were."""
        if why := outlook.problem():
            raise ValueError(f"outlook of site {outlook.site_id!r} refused: {why}")
        held = self.latest.get(outlook.site_id)
        if held is not None and held[0] > stamp_ns:
            return None
        self.latest[outlook.site_id] = (stamp_ns, outlook)
        outlooks = [o for _, o in self.latest.values()]
        rules = Rules.over(self.years, max(o.newest_ns for o in outlooks), self.capacity, self.budget_per_year,
                           self.risk_limit, self.pull_forward)
        try:
            programme = plan(outlooks, rules, self.time_limit_s)
        except Exception:
            if held is None:
                del self.latest[outlook.site_id]
            else:
                self.latest[outlook.site_id] = held
            raise
        return Replan(stamp_ns, outlook.site_id, rules, outlooks, [s for s, _ in self.latest.values()], programme)


def replay(outlooks: Iterable[tuple[int, SiteOutlook]], planner: Replanner) -> list[Replan]:
    """Every re-plan over a network's outlooks, taken in stamp order (ties by site id)."""
    ordered = sorted(outlooks, key=lambda x: (x[0], x[1].site_id))
    return [r for stamp, o in ordered if (r := planner.take(stamp, o)) is not None]
