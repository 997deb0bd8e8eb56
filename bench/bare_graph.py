"""The no-op graph: wayside_monitor's topology, message types, sizes and QoS, without the physics.

Each stand-in subscribes and publishes what its real node does (train_pass in; per pass one
corrugation state, one rolling-noise message per source model, one squeal prediction), but its
callbacks only publish ready-made messages of a real run's sizes (CDR bytes, as the real nodes
publish them). The recorder is the real mcap_recorder (discovery, QoS adaptation, raw
subscriptions) whose callback only counts. Passed to ``wayside_monitor.run_graph``, so the pass
source, executor and flow control are the real ones.

``python -m bench.bare_graph NODE --site SITE`` runs one stand-in as its own process, as the
model's executable runs (its session, executor and flow control): the separate-process layout of
the no-op graph for bench.live. ``python -m bench.bare_graph wayside_monitor --site SITE
--ros-args ...`` runs site_engine's stand-in (one node with every model's topics) and the real
recorder in one process through ``wayside_monitor.run_graph`` (``-p listen:=true``: the
one-process layout of the no-op graph).
"""

from __future__ import annotations

import argparse
from collections import Counter
from collections.abc import Callable, Mapping
from types import SimpleNamespace
from typing import Any

from rclpy.node import Node

from rail_monitor.batch.run import run_models
from rail_monitor.core.passes import PassTable
from rail_monitor.messages import fields
from rail_monitor.nodes.base import Diagnostics, Sent, subscribe_batched
from rail_monitor.nodes.convert import output_publishers, to_cdr
from rail_monitor.nodes.hosted_models import OneEngine
from rail_monitor.nodes.mcap_recorder import McapRecorder
from rail_monitor.nodes.qos import (
    ALERT_QOS,
    EVENT_QOS,
    LATEST_QOS,
    STATE_QOS,
    STATE_SUB_QOS,
    STREAM_QOS,
    STREAM_SUB_QOS,
)
from rail_monitor.nodes.site_engine import PUBLISHED
from rail_monitor.nodes.topic_tap import TAKE_AT_ONCE
from rail_msgs.msg import (
    CorrugationState,
    MeasuredPassNoise,
    RollingNoise,
    RoughnessSurvey,
    SpeedAdvisory,
    SquealPrediction,
    TrainPass,
    WaysideAlert,
    WaysideAlertArray,
)


class _StandIn(Node):
    """Takes train_pass (as the model nodes do: the queued passes with each, up to max_batch) and
    publishes ``outputs`` (publisher, CDR bytes) per pass."""

    def __init__(self, name: str, max_batch: int) -> None:
        super().__init__(name)
        self.max_batch = max_batch
        self.taken = 0
        self.rejected: Counter[str] = Counter()
        self.sent = Sent()
        self.outputs: list[tuple[Any, Any]] = []
        subscribe_batched(self, TrainPass, "train_pass", self._on_train_passes, STREAM_SUB_QOS, max_batch)
        Diagnostics(self, lambda: {"taken": self.taken})

    def _on_train_passes(self, msgs: list[TrainPass]) -> None:
        for _ in msgs:
            for pub, out in self.outputs:
                self.sent.send(pub, out)
        self.taken += len(msgs)


class _Estimator(_StandIn):
    def __init__(self, state: bytes, max_batch: int) -> None:
        super().__init__("corrugation_estimator", max_batch)
        self.state_pub = self.create_publisher(CorrugationState, "corrugation/state", STATE_QOS)
        self.outputs = [(self.state_pub, state)]

    def publish_advisory(self) -> None:
        """The real node's final advice is one linear programme: not part of the ceiling."""


class _Models:
    def __init__(self, names: tuple[str, ...]) -> None:
        self.models = names


class _Noise(_StandIn):
    def __init__(self, noise: dict[str, bytes], max_batch: int) -> None:
        super().__init__("rolling_noise_predictor", max_batch)
        self.pub = self.create_publisher(RollingNoise, "noise/rolling", STREAM_QOS)
        self.model = _Models(tuple(noise))
        self.pending: list[Any] = []
        self.outputs = [(self.pub, m) for m in noise.values()]
        subscribe_batched(self, CorrugationState, "corrugation/state", lambda _: None, STATE_SUB_QOS, max_batch)


class _Squeal(_StandIn):
    def __init__(self, squeal: bytes, max_batch: int) -> None:
        super().__init__("squeal_risk_model", max_batch)
        self.pub = self.create_publisher(SquealPrediction, "noise/squeal", STREAM_QOS)
        self.outputs = [(self.pub, squeal)]


class _Alerts(_StandIn):
    def __init__(self, max_batch: int) -> None:
        super().__init__("alert_manager", max_batch)
        self.inputs: Counter[str] = Counter()
        self.pub = self.create_publisher(WaysideAlert, "alerts", ALERT_QOS)
        self.standing_pub = self.create_publisher(WaysideAlertArray, "alerts/standing", LATEST_QOS)
        for msg_type, topic, qos in ((SquealPrediction, "noise/squeal", STREAM_SUB_QOS),
                                     (RollingNoise, "noise/rolling", STREAM_SUB_QOS),
                                     (CorrugationState, "corrugation/state", STATE_SUB_QOS)):
            subscribe_batched(self, msg_type, topic, lambda msgs, t=topic: self.inputs.update({t: len(msgs)}), qos,
                              max_batch)


class _Engine(_StandIn):
    """site_engine's stand-in: one node taking train_pass (and the survey and measured inputs) and
    publishing every output topic, per pass its state, rolling noise per model and squeal."""

    def __init__(self, state: bytes, noise: dict[str, bytes], squeal: bytes, max_batch: int) -> None:
        super().__init__("site_engine", max_batch)
        self.counts: Counter[str] = Counter()
        self.engine = SimpleNamespace(model=_Models(tuple(noise)))
        self.pubs = output_publishers(self, PUBLISHED)
        self.create_publisher(SpeedAdvisory, "speed_advisory", LATEST_QOS)
        self.outputs = [(self.pubs["noise/squeal"], squeal), (self.pubs["corrugation/state"], state),
                        *((self.pubs["noise/rolling"], m) for m in noise.values())]
        self.create_subscription(RoughnessSurvey, "roughness_survey", lambda _: None, EVENT_QOS)
        subscribe_batched(self, MeasuredPassNoise, "noise/measured", lambda msgs: self.counts.update(
            {"measurements taken": len(msgs)}), STREAM_SUB_QOS, max_batch)

    def publish_advisory(self) -> None:
        """As _Estimator's."""


class _CountingRecorder(McapRecorder):
    """mcap_recorder with a callback that counts and writes nothing."""

    def _on_messages(self, topic: str, msgs: list[bytes]) -> None:
        self.counts[topic] += len(msgs)
        self.meter.tick(len(msgs))


def _outputs(passes: PassTable, values: Mapping[str, Any]) -> tuple[bytes, dict[str, bytes], bytes]:
    """CDR bytes of the corrugation state, rolling noise per model and squeal prediction the real
    models give for the first of ``passes``."""
    r = run_models(passes.take(slice(0, 50)), values)
    frame = r.site.site_id
    first = fields.train_pass_fields(r.accepted.row(0), frame)
    snap, fc = r.trajectory.state(0)
    state = to_cdr(CorrugationState, fields.corrugation_state_fields(snap, fc, frame))
    header, train = first["header"], first["train_id"]
    noise = {m: to_cdr(RollingNoise, fields.rolling_noise_fields(out, 0, header, train, r.receiver))
             for m, out in r.noise.items()}
    squeal = to_cdr(SquealPrediction, fields.squeal_prediction_fields(r.squeal, 0, header, train))
    return state, noise, squeal


def stand_ins(passes: PassTable, values: Mapping[str, Any], max_batch: int) -> dict[str, Callable[[], Node]]:
    """Each model's stand-in by the name of the node it stands in for."""
    state, noise, squeal = _outputs(passes, values)
    return {"corrugation_estimator": lambda: _Estimator(state, max_batch),
            "rolling_noise_predictor": lambda: _Noise(noise, max_batch),
            "squeal_risk_model": lambda: _Squeal(squeal, max_batch),
            "alert_manager": lambda: _Alerts(max_batch)}


def bare_graph(passes: PassTable, values: Mapping[str, Any], max_batch: int = 1
               ) -> tuple[Callable[[], OneEngine], Callable[[], Node]]:
    """make_models and make_recorder for run_graph: site_engine's stand-in, which publishes the
    outputs the real models give for the first of ``passes`` (so every message has a real run's
    size), and the counting recorder; every callback takes up to max_batch queued messages (1: one
    per callback, rclpy's default)."""
    state, noise, squeal = _outputs(passes, values)
    recorder = type("CountingRecorder", (_CountingRecorder,),
                    {"take_at_once": TAKE_AT_ONCE if max_batch > 1 else 1})
    return (lambda: OneEngine(_Engine(state, noise, squeal, max_batch))), recorder


def main() -> None:
    from bench.live import MODEL_EXECUTABLES
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.core.node_params import BATCH_SPECS
    from rail_monitor.core.params import resolve
    from rail_monitor.nodes.process import run_node
    from rail_monitor.nodes.wayside_monitor import run_graph
    from rail_monitor.site_file import load_parameter_file

    ap = argparse.ArgumentParser(description="Run one stand-in of the no-op graph as its own process, or "
                                 "(wayside_monitor) all of them and the real recorder in one process.")
    ap.add_argument("node", choices=(*MODEL_EXECUTABLES, "wayside_monitor"))
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--source", default="bags/sample")
    ns, ros_args = ap.parse_known_args()
    values = load_parameter_file(ns.site)
    passes, max_batch = read_passes(ns.source), resolve(BATCH_SPECS, values)["max_batch"]
    if ns.node == "wayside_monitor":
        run_graph(["bare_wayside_monitor", *ros_args], make_models=bare_graph(passes, values, max_batch)[0])
        return
    makers = stand_ins(passes, values, max_batch)
    raise SystemExit(run_node(makers[ns.node], ["bare_" + ns.node, "--ros-args", "--log-level", "warn"]))


if __name__ == "__main__":
    main()
