"""squeal_risk_model: predicted wheel squeal for every accepted train pass.

Subscribes ``train_pass``; publishes ``noise/squeal`` (rail_msgs/SquealPrediction). Parameters:
the site and its rolling-stock table, and ``squeal.*`` (:data:`rail_monitor.squeal.config.
SQUEAL_SPECS`: wheel mode, receiver, friction-modifier reach, risk thresholds); the creep curves
and k3 are the site's contact (``contact.*``).
"""

from __future__ import annotations

import sys
from typing import Any

from rail_monitor.core.passes import PassTable
from rail_monitor.messages.fields import PassHead, heads_columns, squeal_prediction_columns
from rail_monitor.nodes.base import declare
from rail_monitor.nodes.convert import to_cdr_many
from rail_monitor.nodes.pass_consumer import PassConsumerNode
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import STREAM_QOS
from rail_monitor.squeal.config import SQUEAL_SPECS, squeal_config
from rail_monitor.squeal.predict import predict
from rail_msgs.msg import SquealPrediction


class SquealRiskNode(PassConsumerNode):
    EXECUTABLE = "squeal_risk_model"
    PARAMETERS = (*PassConsumerNode.PARAMETERS, ("squeal.", SQUEAL_SPECS))

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("squeal_risk_model", **kwargs)
        self.cfg = squeal_config(declare(self, SQUEAL_SPECS, prefix="squeal."), prefix="")
        self.pub = self.create_publisher(SquealPrediction, "noise/squeal", STREAM_QOS)
        self.listen()

    def key_parameters(self) -> dict[str, Any]:
        return {"k3": self.site.contact.k3_convention}

    def on_passes(self, table: PassTable, heads: list[PassHead]) -> None:
        values = predict(self.cfg, self.site, table)
        for data in to_cdr_many(SquealPrediction, squeal_prediction_columns(values, heads_columns(heads)), len(heads)):
            self.sent.send(self.pub, data)

    def diagnostic_values(self) -> dict[str, Any]:
        return {**super().diagnostic_values(), "published": sum(self.sent.values())}


def main(args: list[str] | None = None) -> int:
    return run_node(SquealRiskNode, args)


if __name__ == "__main__":
    sys.exit(main())
