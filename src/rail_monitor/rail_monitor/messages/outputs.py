"""A site engine's outputs as the graph's messages (CDR bytes on their topics, with their stamps),
written once for the bag batch mode records and the engine node's publishers (no rclpy).

Topics are relative to the site namespace (messages.topics). The alert stream is the alert
manager's: each raise or clear on ``alerts``, then the standing set after it on
``alerts/standing`` (so a late subscriber sees the current set at once).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any, NamedTuple

import numpy as np

from rail_monitor.advice.plan import SpeedAdvice
from rail_monitor.alerts.manager import Alert
from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.cdr_from_columns import serialize_columns
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.engine.result import SiteOutputs
from rail_monitor.engine.squeal_site import Calibration
from rail_monitor.measured.observer import Observation
from rail_monitor.measured.residuals import Residual
from rail_monitor.messages import fields
from rail_monitor.messages.economics_fields import grinding_outlook_fields
from rail_monitor.messages.topics import GRAPH_TOPICS, OPTIONAL_TOPICS


class Messages(NamedTuple):
    """Messages of one topic, in order: their CDR bytes and stamps [ns]."""

    topic: str
    datas: list[bytes]
    stamps_ns: list[int]


def typename(topic: str) -> str:
    """The message type of a graph topic (recorded always, or once published)."""
    return (GRAPH_TOPICS.get(topic) or OPTIONAL_TOPICS[topic])[0]


def one(topic: str, msg: dict[str, Any], stamp_ns: int) -> Messages:
    """One message of plain fields (messages.fields) on topic."""
    return Messages(topic, [serialize(typename(topic), msg)], [stamp_ns])


def per_pass(result: SiteOutputs, frame: str) -> list[Messages]:
    """The per-pass outputs of a chunk: the squeal prediction of every accepted pass, the
    corrugation state after every counted pass, and the rolling noise of every accepted pass (one
    message per source model, model by model in each pass's order)."""
    accepted, traj = result.accepted, result.trajectory
    heads = fields.table_heads_columns(accepted, frame)
    squeal = fields.squeal_prediction_columns(result.squeal, heads)
    return [Messages("noise/squeal", serialize_columns(typename("noise/squeal"), squeal, len(accepted)),
                     accepted.stamp_ns.tolist()),
            Messages("corrugation/state", fields.corrugation_state_cdr(traj, frame), traj.stamp_ns.tolist()),
            Messages("noise/rolling", fields.rolling_noise_cdr(result.noise.values(), heads, result.receiver),
                     np.repeat(accepted.stamp_ns, len(result.noise)).tolist())]


def measured(residuals: Iterable[Residual], observations: Iterable[Observation], frame: str,
             calibrations: Iterable[Calibration] = ()) -> list[Messages]:
    """Residuals of measured pass-bys, the indirect roughness of each closed window, and each fit
    of the squeal model."""
    return [*(one("noise/residual", fields.noise_residual_fields(r, frame), r.stamp_ns) for r in residuals),
            *(one("corrugation/indirect_roughness", fields.indirect_roughness_fields(o, frame), o.stamp_ns)
              for o in observations),
            *(one("noise/squeal_calibration", fields.squeal_calibration_fields(c, frame), c.stamp_ns)
              for c in calibrations)]


def outlooks(made: Sequence[tuple[MaintenanceEvent, SiteOutlook]], frame: str) -> Messages:
    """The grinding outlook made on each event applied (stamped with the event)."""
    t = typename("grinding/outlook")
    return Messages("grinding/outlook", [serialize(t, grinding_outlook_fields(e, o, frame)) for e, o in made],
                    [e.stamp_ns for e, _ in made])


def advice(advised: SpeedAdvice, newest_ns: int, frame: str) -> Messages:
    """The speed advice on the state whose newest pass is stamped newest_ns."""
    return one("speed_advisory", fields.speed_advisory_fields(advised, newest_ns, frame), newest_ns)


class AlertStream:
    """The alert events as messages, with the standing set after each (it follows the events)."""

    def __init__(self, frame: str) -> None:
        self.frame = frame
        self.standing: dict[tuple[int, str], Alert] = {}

    def messages(self, events: Iterable[Alert]) -> list[Messages]:
        out = []
        for a in events:
            out.append(one("alerts", fields.wayside_alert_fields(a, self.frame), a.stamp_ns))
            if a.active:
                self.standing[(a.kind, a.key)] = a
            else:
                self.standing.pop((a.kind, a.key), None)
            out.append(one("alerts/standing", fields.wayside_alert_array_fields(list(self.standing.values()),
                                                                               a.stamp_ns, self.frame), a.stamp_ns))
        return out
