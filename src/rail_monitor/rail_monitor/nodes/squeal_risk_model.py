"""squeal_risk_model: predicted wheel squeal for every accepted train pass.

Subscribes ``train_pass`` and ``noise/measured``; publishes ``noise/squeal``
(rail_msgs/SquealPrediction) and, with ``squeal.fit_days`` > 0, ``noise/squeal_calibration``
(rail_msgs/SquealCalibration): the measured squeal re-fits each friction state's creep curve at
the end of each window and the passes after it are predicted on the fit's P50 curves, the site
engine's own squeal part (rail_monitor.engine.squeal_site), so that the separate-process layout
predicts what site_engine does. Measurements queued before a pass are taken before it. The fit is
not checkpointed here: a restarted squeal_risk_model fits anew from the measurements it takes
(site_engine, the one-process layout, checkpoints it with the corrugation state).

Parameters: the site and its rolling-stock table, ``squeal.*`` (:data:`rail_monitor.squeal.config.
SQUEAL_SPECS`: wheel mode, receiver, friction-modifier reach, risk thresholds, the fit), and
``alerts.squeal_min_risk`` (what counts as squealing) and ``residual.held_predictions`` (passes
held for their measurements); the creep curves and k3 are the site's contact (``contact.*``).
"""

from __future__ import annotations

import sys
from typing import Any

from rail_monitor.alerts.config import ALERT_SPECS, RISK_NAMES
from rail_monitor.core.passes import PassTable
from rail_monitor.engine.squeal_site import SquealSite
from rail_monitor.measured.config import RESIDUAL_SPECS
from rail_monitor.messages import outputs
from rail_monitor.messages.fields import PassHead, heads_columns, measurement_from_msg, squeal_prediction_columns
from rail_monitor.nodes.base import declare, subscribe_batched, take_queued
from rail_monitor.nodes.convert import output_publishers, to_cdr_many
from rail_monitor.nodes.pass_consumer import PassConsumerNode
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import STREAM_QOS, STREAM_SUB_QOS
from rail_monitor.squeal.config import SQUEAL_SPECS, squeal_config
from rail_monitor.squeal.predict import predict
from rail_msgs.msg import MeasuredPassNoise, SquealPrediction

FIT_SPECS = (("alerts.", tuple(s for s in ALERT_SPECS if s.name == "squeal_min_risk")),
             ("residual.", tuple(s for s in RESIDUAL_SPECS if s.name == "held_predictions")))


class SquealRiskNode(PassConsumerNode):
    EXECUTABLE = "squeal_risk_model"
    PARAMETERS = (*PassConsumerNode.PARAMETERS, ("squeal.", SQUEAL_SPECS), *FIT_SPECS)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("squeal_risk_model", **kwargs)
        self.cfg = squeal_config(declare(self, SQUEAL_SPECS, prefix="squeal."), prefix="")
        (alerts, a_specs), (residual, r_specs) = FIT_SPECS
        min_risk = RISK_NAMES.index(declare(self, a_specs, prefix=alerts)["squeal_min_risk"])
        held = declare(self, r_specs, prefix=residual)["held_predictions"]
        self.squeal = SquealSite(self.site, self.cfg, min_risk, held)
        self.pub = self.create_publisher(SquealPrediction, "noise/squeal", STREAM_QOS)
        self.fit_pub = output_publishers(self, ("noise/squeal_calibration",))["noise/squeal_calibration"] \
            if self.squeal.enabled else None
        self.measured_sub = subscribe_batched(self, MeasuredPassNoise, "noise/measured", self._on_measured,
                                              STREAM_SUB_QOS, self.max_batch) if self.squeal.enabled else None
        self.listen()

    def key_parameters(self) -> dict[str, Any]:
        return {"k3": self.site.contact.k3_convention, "fit_days": f"{self.cfg.fit_days:g}"}

    def _on_measured(self, msgs: list[MeasuredPassNoise]) -> None:
        self.squeal.take([measurement_from_msg(m) for m in msgs])

    def _on_train_passes(self, raws: list[bytes]) -> None:
        if self.measured_sub is not None:  # measured passes before these: in the fit before them
            self._on_measured(take_queued(self.measured_sub, self.max_batch))
        super()._on_train_passes(raws)

    def on_passes(self, table: PassTable, heads: list[PassHead]) -> None:
        start = 0
        for part in self.squeal.segments(table):
            values = predict(self.cfg, self.squeal.site, part)
            self.squeal.hold(part)
            mine = heads[start:start + len(part)]
            columns = squeal_prediction_columns(values, heads_columns(mine))
            for data in to_cdr_many(SquealPrediction, columns, len(mine)):
                self.sent.send(self.pub, data)
            start += len(part)
        for msgs in outputs.measured((), (), self.site.site_id, self.squeal.take_calibrations()):
            for data in msgs.datas:
                self.sent.send(self.fit_pub, data)

    def diagnostic_values(self) -> dict[str, Any]:
        return {**super().diagnostic_values(), "published": sum(self.sent.values()),
                **{f"squeal fit {k}": v for k, v in sorted(self.squeal.counts.items())}}


def main(args: list[str] | None = None) -> int:
    return run_node(SquealRiskNode, args)


if __name__ == "__main__":
    sys.exit(main())
