"""rolling_noise_predictor: predicted rolling noise at the site's receiver for every accepted train pass.

Subscribes ``train_pass`` and ``corrugation/state`` (latched; the latest state received is the rail's
corrugation); publishes ``noise/rolling`` (rail_msgs/RollingNoise) per pass, one message per source
model: ``noise.model`` is cnossos, mechanics or both. Parameters: the site (track, contact, rolling
stock) and ``noise.*`` (rail_monitor.rolling_noise.NOISE_SPECS: baseline rail roughness, CNOSSOS
track type, interpolation rule, receiver and ground, mechanics radiators). A corrugation state with
inconsistent arrays is refused with its reason on /diagnostics and the previous one kept.
"""

from __future__ import annotations

import sys
from collections import Counter
from typing import Any

from rail_monitor.nodes.base import declare, run_node
from rail_monitor.nodes.convert import corrugation_from_msg, rolling_noise_msg, time_ns
from rail_monitor.nodes.pass_model import PassModelNode
from rail_monitor.nodes.qos import LATEST_QOS, STREAM_QOS
from rail_monitor.passes import PassTable
from rail_monitor.rolling_noise import NOISE_SPECS, Corrugation, RollingNoiseModel, noise_config
from rail_monitor.timeutil import format_iso_ns
from rail_msgs.msg import CorrugationState, RollingNoise, TrainPass


class RollingNoisePredictor(PassModelNode):
    def __init__(self, **kwargs: Any) -> None:
        super().__init__("rolling_noise_predictor", **kwargs)
        cfg = noise_config(declare(self, NOISE_SPECS, prefix="noise."), prefix="")
        self.model = RollingNoiseModel(self.site, cfg)
        self.corrugation: Corrugation | None = None
        self.corrugation_ns = 0
        self.published = 0
        self.states_rejected: Counter[str] = Counter()
        self.pub = self.create_publisher(RollingNoise, "noise/rolling", STREAM_QOS)
        self.create_subscription(CorrugationState, "corrugation/state", self._on_state, LATEST_QOS)

    def _on_state(self, msg: CorrugationState) -> None:
        try:
            self.corrugation = corrugation_from_msg(msg)
        except ValueError as exc:
            self.states_rejected[str(exc)] += 1
            self.get_logger().warning(f"corrugation state refused: {exc}", throttle_duration_sec=5.0)
            return
        self.corrugation_ns = time_ns(msg.header.stamp)

    def on_pass(self, table: PassTable, msg: TrainPass) -> None:
        for name in self.model.models:
            values = self.model.predict(table, name, self.corrugation)
            self.pub.publish(rolling_noise_msg(values, 0, msg, self.model.receiver))
            self.published += 1

    def diagnostic_values(self) -> dict[str, Any]:
        values = {**super().diagnostic_values(), "published": self.published, "models": ",".join(self.model.models),
                  "corrugation_state": format_iso_ns(self.corrugation_ns) if self.corrugation_ns else "none"}
        values.update({f"state refused: {why}": n for why, n in sorted(self.states_rejected.items())})
        return values


def main(args: list[str] | None = None) -> int:
    return run_node(RollingNoisePredictor, args)


if __name__ == "__main__":
    sys.exit(main())
