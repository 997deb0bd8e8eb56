"""The site's events as message fields, and back (no rclpy): roughness surveys and grinding
(rail_msgs/RoughnessSurvey) and a friction-modifier applicator's start and stop
(rail_msgs/FrictionApplicator). Conventions as in :mod:`rail_monitor.messages.fields`."""

from __future__ import annotations

from typing import Any

import numpy as np

from rail_monitor.core.friction import ApplicatorEvent
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.messages.fields import Fields, header_fields, time_ns


def roughness_survey_fields(event: MaintenanceEvent, frame_id: str) -> Fields:
    return {"header": header_fields(event.stamp_ns, frame_id), "kind": event.kind,
            "wavelength_m": np.asarray(event.wavelength_m, float).tolist(),
            "amplitude_m": np.asarray(event.amplitude_m, float).tolist()}


def event_from_msg(msg: Any) -> MaintenanceEvent:
    """A RoughnessSurvey as a MaintenanceEvent (its checks are apply_event's)."""
    return MaintenanceEvent(time_ns(msg.header.stamp), int(msg.kind), np.array(msg.wavelength_m, float),
                            np.array(msg.amplitude_m, float))


def friction_applicator_fields(event: ApplicatorEvent, frame_id: str) -> Fields:
    return {"header": header_fields(event.stamp_ns, frame_id), "action": event.action, "product": event.product}


def applicator_from_msg(msg: Any) -> ApplicatorEvent:
    """A FrictionApplicator as an ApplicatorEvent (its checks are applicator_refusal's)."""
    return ApplicatorEvent(time_ns(msg.header.stamp), int(msg.action), str(msg.product))
