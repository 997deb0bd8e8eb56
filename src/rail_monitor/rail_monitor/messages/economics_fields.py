"""Grinding outlooks and programmes as message fields, and back (no rclpy):
rail_msgs/GrindingOutlook (economics.outlook.SiteOutlook, made on a site's survey, grinding or
indirect observation) and rail_msgs/GrindingProgramme (economics.replan.Replan). Conventions as
in :mod:`rail_monitor.messages.fields`."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.economics.outlook import Option, SiteOutlook
from rail_monitor.messages.fields import Fields, future_time_fields, header_fields, time_fields, time_ns

if TYPE_CHECKING:  # the programme's solver (scipy.optimize) stays out of a site node's start-up
    from rail_monitor.economics.replan import Replan

QUANTILES = ("p10", "p50", "p90")


def _quantiles(name: str, days: np.ndarray) -> Fields:
    return {f"{name}_{q}": float(d) for q, d in zip(QUANTILES, days.tolist(), strict=True)}


def _read_quantiles(msg: Any, name: str) -> np.ndarray:
    return np.array([getattr(msg, f"{name}_{q}") for q in QUANTILES], float)


def grinding_outlook_fields(event: MaintenanceEvent, o: SiteOutlook, frame_id: str) -> Fields:
    """The outlook made when event was applied (stamped with it)."""
    out = {"header": header_fields(event.stamp_ns, frame_id), "event_kind": event.kind,
           "newest_pass": time_fields(o.newest_ns), **_quantiles("due_days", o.due_days),
           **_quantiles("cycle_days", o.cycle_days), "visit_cost": o.visit_cost,
           "late_visit_cost": o.late_visit_cost, "grind_length_m": o.length_m,
           "option": [p.name for p in o.options], "option_cost_per_year": [p.cost_per_year for p in o.options],
           "option_effects": [p.effects for p in o.options]}
    for i, q in enumerate(QUANTILES):
        out[f"option_cycle_days_{q}"] = [float(p.cycle_days[i]) for p in o.options]
    return out


def outlook_from_msg(msg: Any) -> tuple[int, SiteOutlook]:
    """A GrindingOutlook's stamp [ns] and outlook."""
    cycles = np.array([getattr(msg, f"option_cycle_days_{q}") for q in QUANTILES], float)
    options = tuple(Option(str(n), cycles[:, i].copy(), float(c), str(e)) for i, (n, c, e) in
                    enumerate(zip(msg.option, msg.option_cost_per_year, msg.option_effects, strict=True)))
    return time_ns(msg.header.stamp), SiteOutlook(
        str(msg.header.frame_id), time_ns(msg.newest_pass), _read_quantiles(msg, "due_days"),
        _read_quantiles(msg, "cycle_days"), float(msg.visit_cost), float(msg.late_visit_cost),
        float(msg.grind_length_m), options)


def grinding_programme_fields(r: Replan) -> Fields:
    """A re-plan as a GrindingProgramme (stamped with the outlook that made it, framed with its site)."""
    p, rules = r.programme, r.rules
    visits = sorted((int(m), i) for i, months in enumerate(p.visits) for m in months.tolist())
    return {"header": header_fields(r.stamp_ns, r.site_id), "start": time_fields(rules.start_ns),
            "months": rules.months, "capacity": rules.capacity, "budget_per_year": rules.budget_per_year,
            "risk_limit": rules.risk_limit, "site_id": list(p.sites),
            "outlook_stamp": [time_fields(s) for s in r.stamps_ns], "option": list(p.option),
            "first_visit_month": [int(v[0]) if len(v) else -1 for v in p.visits],
            "visits": [len(v) for v in p.visits], "expected_cost": p.expected_cost.tolist(),
            "risk": p.risk.tolist(), "expected_late": p.lates.tolist(),
            "visit_site_id": [p.sites[i] for _, i in visits], "visit_month": [m for m, _ in visits],
            "visit_start": [future_time_fields(rules.month_ns(m)) for m, _ in visits],
            "total_expected_cost": float(p.expected_cost.sum()), "status": p.status, "schedules": p.schedules}
