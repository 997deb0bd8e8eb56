"""The model nodes wayside_monitor hosts, by layout, and what the graph waits on in each: one
site_engine (the site engine batch mode runs), or the four model nodes whose outputs feed one
another (corrugation_estimator, rolling_noise_predictor, squeal_risk_model, alert_manager).

wayside_monitor asks a layout, never its nodes' positions: whether every pass has left the models,
how many measured pass-bys they took, and how far the slowest hosted consumer has got (so the pass
source keeps its backlog below the queues' depth).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.node import Node


class HostedModels:
    """The model nodes of one layout; ``nodes[0]`` holds the corrugation state and the advice.

    per_pass: rolling-noise messages per pass (one per source model); noise_topic, squeal_topic:
    the topics the recorder is counted on."""

    def __init__(self, nodes: list[Any], per_pass: int, noise_topic: str, squeal_topic: str) -> None:
        self.nodes = nodes
        self.per_pass, self.noise_topic, self.squeal_topic = per_pass, noise_topic, squeal_topic

    @property
    def head(self) -> Any:
        """The node holding the corrugation state: it publishes the advice and counts passes taken."""
        return self.nodes[0]

    def took(self, published: int) -> bool:
        """Every model node took ``published`` passes."""
        return all(m.taken >= published for m in self.nodes)

    def settled(self) -> bool:
        """No pass waits inside a model."""
        return True

    def measured_taken(self) -> int:
        """Measured pass-bys the models took."""
        raise NotImplementedError

    def inputs_taken(self) -> bool:
        """Every model output of one node taken by the nodes downstream."""
        return True

    def consumed(self) -> list[int]:
        """Passes each hosted model consumer has taken, its inputs' queues included."""
        return [m.taken for m in self.nodes]

    def passes_through(self, recorder: Any, topic: str) -> Callable[[], int]:
        """Passes the slowest hosted consumer (the recorder's count of ``topic`` and of the
        per-pass outputs included) has taken: the pass source keeps its backlog below their
        queues' depth, so no queue overflows."""

        def taken() -> int:
            counts = self.consumed()
            if recorder is not None:
                got = recorder.counts
                counts += [got.get(topic, 0), got.get(self.squeal_topic, 0),
                           got.get(self.noise_topic, 0) // self.per_pass]
            return min(counts)

        return taken

    def output_topics(self) -> set[str]:
        """The topics the model nodes publish (resolved), but /diagnostics, /rosout and parameter events."""
        return {p.topic_name for m in self.nodes for p in m.publishers
                if not p.topic_name.startswith(("/diagnostics", "/rosout", "/parameter_events"))}


class OneEngine(HostedModels):
    """site_engine alone (or a stand-in with its topics): it holds no pass and feeds no other node."""

    def __init__(self, engine: Node) -> None:
        pubs = engine.pubs
        super().__init__([engine], len(engine.engine.model.models), pubs["noise/rolling"].topic_name,
                         pubs["noise/squeal"].topic_name)

    def measured_taken(self) -> int:
        return self.head.counts["measurements taken"]


class FourNodes(HostedModels):
    """corrugation_estimator, rolling_noise_predictor, squeal_risk_model and alert_manager, in that
    order: the predictor may hold a pass for its state, and alert_manager takes the others' outputs."""

    def __init__(self, estimator: Node, predictor: Node, squeal: Node, alerts: Node) -> None:
        super().__init__([estimator, predictor, squeal, alerts], len(predictor.model.models),
                         predictor.pub.topic_name, squeal.pub.topic_name)
        self.estimator, self.predictor, self.squeal, self.alerts = estimator, predictor, squeal, alerts

    def settled(self) -> bool:
        return not self.predictor.pending

    def measured_taken(self) -> int:
        return self.alerts.inputs["noise/measured"]

    def inputs_taken(self) -> bool:
        est, alerts = self.estimator, self.alerts.inputs
        return (alerts["noise/squeal"] >= sum(self.squeal.sent.values())
                and alerts["noise/rolling"] >= sum(self.predictor.sent.values())
                and alerts["corrugation/state"] >= est.sent[est.state_pub.topic_name])

    def consumed(self) -> list[int]:
        alerts = self.alerts.inputs
        return [*super().consumed(), alerts["noise/squeal"], alerts["noise/rolling"] // self.per_pass]
