"""The graph's recorded topics: name (relative to the site namespace), message type and the QoS
its publisher offers, as plain data (the nodes make rclpy profiles of them, batch mode writes
them into its bag's metadata)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

# rosbag2's "infinite" duration in QoS (deadline, lifespan, lease) as written by Jazzy.
_INFINITE = {"sec": 9223372036, "nsec": 854775807}


def qos_dict(reliable: bool = True, transient_local: bool = False, depth: int = 1000,
             history: str = "keep_last") -> dict[str, Any]:
    """One offered QoS profile in the metadata.yaml version 9 layout.

    history: keep_last, keep_all, or unknown (what discovery reports for a remote publisher).
    """
    return {
        "history": history,
        "depth": depth,
        "reliability": "reliable" if reliable else "best_effort",
        "durability": "transient_local" if transient_local else "volatile",
        "deadline": dict(_INFINITE),
        "lifespan": dict(_INFINITE),
        "liveliness": "automatic",
        "liveliness_lease_duration": dict(_INFINITE),
        "avoid_ros_namespace_conventions": False,
    }



@dataclass(frozen=True)
class Qos:
    """A QoS profile: reliable or best effort, transient local or volatile, KEEP_LAST depth."""

    depth: int
    reliable: bool = True
    transient_local: bool = False

    def as_metadata(self) -> dict[str, Any]:
        """The profile in rosbag2's metadata layout."""
        return qos_dict(reliable=self.reliable, transient_local=self.transient_local, depth=self.depth)


# Pass events and model outputs: reliable. Publishers keep 1000; subscribers queue 10000 so a
# burst waits rather than drops (KEEP_ALL readers would give DDS-level backpressure, but Fast
# DDS's stalled at about 5,100 samples here). Transient local: a subscriber that matches a moment
# late (another process's discovery) still gets the last 1000, so no start-up order loses output.
STREAM = Qos(1000, transient_local=True)
STREAM_SUB = Qos(10000, transient_local=True)
# A state whose latest value is what matters (speed advisory, the standing alerts): a late
# subscriber (a dashboard started later) gets the current one at once.
LATEST = Qos(1, transient_local=True)
# The corrugation state: every state matters to the noise predictor, the alert manager and the
# recorder (each takes them all, in order), and the estimator publishes a backlog's states in one
# burst. A reliable KEEP_LAST writer overwrites samples not yet delivered once its history is full,
# so at depth 1 a burst over UDP lost states. Latched too: a late subscriber gets the recent states.
STATE = Qos(1000, transient_local=True)
STATE_SUB = Qos(10000, transient_local=True)
# Rare inputs that must not be lost (roughness surveys, grinding events); their senders wait for
# the subscribers' acknowledgement. Volatile: a survey is taken once, by the subscribers present.
EVENT = Qos(100)
# Alert raise/clear events: reliable and latched, deep enough that a late subscriber gets the
# recent history; the standing set is on alerts/standing (LATEST).
ALERT = Qos(1000, transient_local=True)
DIAGNOSTICS = Qos(100)
DIAGNOSTICS_TOPIC = "/diagnostics"  # every node reports here, each period
CLOCK = Qos(10)

GRAPH_TOPICS: dict[str, tuple[str, Qos]] = {
    "train_pass": ("rail_msgs/msg/TrainPass", STREAM), "noise/squeal": ("rail_msgs/msg/SquealPrediction", STREAM),
    "corrugation/state": ("rail_msgs/msg/CorrugationState", STATE),
    "noise/rolling": ("rail_msgs/msg/RollingNoise", STREAM), "alerts": ("rail_msgs/msg/WaysideAlert", ALERT),
    "alerts/standing": ("rail_msgs/msg/WaysideAlertArray", LATEST),
    "speed_advisory": ("rail_msgs/msg/SpeedAdvisory", LATEST)}
# Topics recorded only when they carry something: a replay's or batch's surveys and grinding,
# measured pass-by noise, the residuals computed from it, and the indirect roughness fitted on it.
OPTIONAL_TOPICS: dict[str, tuple[str, Qos]] = {
    "roughness_survey": ("rail_msgs/msg/RoughnessSurvey", EVENT),
    "noise/measured": ("rail_msgs/msg/MeasuredPassNoise", STREAM),
    "noise/residual": ("rail_msgs/msg/NoiseResidual", STREAM),
    # A model output like the others (latched): a recorder that matched a moment late lost one.
    "corrugation/indirect_roughness": ("rail_msgs/msg/IndirectRoughness", STREAM),
    # Each fit of the squeal model to the measured squeal (latched, as every model output).
    "noise/squeal_calibration": ("rail_msgs/msg/SquealCalibration", STREAM),
    # A friction-modifier applicator's start or stop: a site event for the record (no model takes
    # it), latched so that a recorder that matches late still records it.
    "friction_applicator": ("rail_msgs/msg/FrictionApplicator", STREAM),
    # The site's grinding outlook, made on each survey, grinding or indirect observation applied;
    # latched with depth: a planner started later takes every site's recent outlooks, the newest last.
    "grinding/outlook": ("rail_msgs/msg/GrindingOutlook", STREAM)}
# A network's grinding programme (grinding_planner, not a site's topic): the current one matters.
PROGRAMME_TOPIC = ("grinding/programme", "rail_msgs/msg/GrindingProgramme", LATEST)
