"""corrugation_estimator: rail roughness per wavelength band at the site, grinding forecast, speed advice.

Subscribes ``train_pass`` (each accepted pass advances the state once: passes are identified by
(stamp, train_id)) and ``roughness_survey`` (rail_msgs/RoughnessSurvey: a survey re-fits K_b, a
grinding event resets the state). A survey or grinding is applied before the first pass stamped
later than it, as batch mode applies it (one stamped after every pass so far waits for the next
pass, or shutdown; one stamped before a pass already counted is applied on arrival and counted as
late); surveys queued behind a backlog of passes are taken first. With ``residual.indirect_days``
> 0 it also subscribes ``noise/measured`` and takes each window's indirect rail roughness as an
observation (rail_monitor.measured.observer; published on ``corrugation/indirect_roughness``,
rail_msgs/IndirectRoughness). Publishes
``corrugation/state`` (rail_msgs/CorrugationState, per pass or at most every ``state_period_s``)
and ``speed_advisory`` (rail_msgs/SpeedAdvisory, every ``advisory_period_s``), both latched, and
``grinding/outlook`` (rail_msgs/GrindingOutlook) on each survey, grinding or indirect observation
applied; serves ``evaluate_speed_distribution``. With
``checkpoint_path`` set, the state is written atomically every ``checkpoint_every_passes``
passes, after every survey and at shutdown (the executor copies it; a writer thread encodes and
writes it, rail_monitor.engine.checkpoint.CheckpointWriter), and a restart resumes from it.
"""

from __future__ import annotations

import sys
import time
from collections import Counter
from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus

from rail_monitor.advice.consequences import Consequences
from rail_monitor.core.node_params import ESTIMATOR_SPECS, EstimatorParams
from rail_monitor.core.params import values_of
from rail_monitor.core.passes import PassTable
from rail_monitor.core.timeutil import format_iso_ns
from rail_monitor.corrugation import surveys
from rail_monitor.corrugation.config import CORRUGATION_SPECS, corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.economics.config import ECONOMICS_SPECS, economics_config
from rail_monitor.economics.options import configured_outlook
from rail_monitor.engine import checkpoint
from rail_monitor.engine.corrugation_site import CorrugationSite
from rail_monitor.measured.config import RESIDUAL_SPECS, residual_config
from rail_monitor.measured.observer import IndirectObserver, Observation
from rail_monitor.messages.economics_fields import grinding_outlook_fields
from rail_monitor.messages.event_fields import event_from_msg
from rail_monitor.messages.fields import (
    PassHead,
    corrugation_state_cdr,
    indirect_roughness_fields,
    measurement_from_msg,
)
from rail_monitor.models.calibration import KbPosterior
from rail_monitor.nodes.base import declare, subscribe_batched, take_queued
from rail_monitor.nodes.pass_consumer import PassConsumerNode
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import EVENT_QOS, STATE_QOS, STREAM_QOS, STREAM_SUB_QOS
from rail_monitor.nodes.state_services import StateServices
from rail_monitor.noise.config import NOISE_SPECS, noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.squeal.config import SQUEAL_SPECS, squeal_config
from rail_msgs.msg import (
    CorrugationState,
    GrindingOutlook,
    IndirectRoughness,
    MeasuredPassNoise,
    RoughnessSurvey,
)


class CorrugationEstimatorNode(PassConsumerNode):
    EXECUTABLE = "corrugation_estimator"
    # noise.* and squeal.*: what the speed advice weighs besides corrugation (rail_monitor.advice);
    # residual.*: the indirect roughness taken as an observation; economics.*: the grinding outlook.
    PARAMETERS = (*PassConsumerNode.PARAMETERS, ("", ESTIMATOR_SPECS), ("corrugation.", CORRUGATION_SPECS),
                  ("noise.", NOISE_SPECS), ("squeal.", SQUEAL_SPECS), ("residual.", RESIDUAL_SPECS),
                  ("economics.", ECONOMICS_SPECS))

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("corrugation_estimator", **kwargs)
        self.params = values_of(EstimatorParams, declare(self, ESTIMATOR_SPECS))
        cfg = corrugation_config(declare(self, CORRUGATION_SPECS, prefix="corrugation."), prefix="")
        self.est = CorrugationEstimator(self.site, cfg)
        self._noise_cfg = noise_config(declare(self, NOISE_SPECS, prefix="noise."), prefix="")
        self._squeal_cfg = squeal_config(declare(self, SQUEAL_SPECS, prefix="squeal."), prefix="")
        economics = economics_config(declare(self, ECONOMICS_SPECS, prefix="economics."), prefix="")
        self._consequences: Consequences | None = None
        self._noise_model: RollingNoiseModel | None = None
        residual_cfg = residual_config(declare(self, RESIDUAL_SPECS, prefix="residual."), prefix="")
        observer = IndirectObserver(self.noise_model(), residual_cfg, self.est.bands) \
            if residual_cfg.indirect_days > 0 else None
        # Events are checked on arrival (stamp_ahead, with the live clock): none at the moment they fall due.
        self.corrugation = CorrugationSite(self.est, observer)
        self.corrugation.on_event = self._on_event
        self.corrugation.on_observation = self._on_observation
        self.corrugation.outlook = lambda: configured_outlook(self.est, economics, self.consequences)
        self.outlook_pub = self.create_publisher(GrindingOutlook, "grinding/outlook", STREAM_QOS)
        self.counts: Counter[str] = Counter()
        self.state_pub = self.create_publisher(CorrugationState, "corrugation/state", STATE_QOS)
        self.state_services = StateServices(self, self.est, self.params, self.consequences, self.sent,
                                            self.state_pub, observer)
        self.state_services.resume(lambda path: checkpoint.resume(self.est, path, self.observer))
        self.stream_ns = self.est.newest_ns  # the stamp margin counts from the resumed history
        self.survey_sub = self.create_subscription(RoughnessSurvey, "roughness_survey", self._on_survey, EVENT_QOS)
        self.measured_sub = self.indirect_pub = None
        if self.observer is not None:
            self.measured_sub = subscribe_batched(self, MeasuredPassNoise, "noise/measured", self._on_measured,
                                                  STREAM_SUB_QOS, self.max_batch)
            self.indirect_pub = self.create_publisher(IndirectRoughness, "corrugation/indirect_roughness", STREAM_QOS)
        self.listen()

    @property
    def observer(self) -> IndirectObserver | None:
        """The indirect roughness windows (the corrugation step's)."""
        return self.corrugation.observer

    @property
    def surveys_rejected(self) -> Counter[str]:
        """Surveys, grinding and indirect observations refused, on arrival or when applied, by reason."""
        return self.corrugation.refused

    def key_parameters(self) -> dict[str, Any]:
        return {"checkpoint": self.state_services.path or "none", "passes": self.est.total_pass_count,
                "lead_time_days": f"{self.est.cfg.lead_time_days:g}"}

    def _on_train_passes(self, raws: list[bytes]) -> None:
        # Surveys sent before these passes are in their queue by now (a replay sends each before the
        # first later pass, acknowledged): take them first, so they wait for the right pass.
        for msg in take_queued(self.survey_sub, 1000):
            self._on_survey(msg)
        if self.measured_sub is not None:  # measured passes before these: in their window's fit
            self._on_measured(take_queued(self.measured_sub, self.max_batch))
        super()._on_train_passes(raws)

    def _on_measured(self, msgs: list[MeasuredPassNoise]) -> None:
        self.observer.add_measurements([measurement_from_msg(m) for m in msgs])

    def on_passes(self, table: PassTable, heads: list[PassHead]) -> None:
        for part in self.corrugation.segments(table):
            self._count(part)

    def _on_observation(self, obs: Observation) -> None:
        """A closed indirect roughness window: its fit published (then taken as a survey)."""
        self.sent.publish(self.indirect_pub, indirect_roughness_fields(obs, self.site.site_id))

    def _count(self, table: PassTable) -> None:
        # The state and forecast after each counted pass, as advancing one pass at a time gives them.
        traj = self.corrugation.advance(table)
        if len(traj) < len(table):
            self.counts["not counted (already counted, or older than the history)"] += len(table) - len(traj)
        if not len(traj):
            return
        self.counts["counted"] += len(traj)
        self.state_services.counted(len(traj))
        if self.params.state_period_s == 0.0:
            for data in corrugation_state_cdr(traj, self.site.site_id):
                self.sent.send(self.state_pub, data)
        else:
            self.state_services.publish_state_if_due()

    def publish_advisory(self) -> None:
        """The advice on the current state (also every advisory_period_s)."""
        self.state_services.publish_advisory()

    def noise_model(self) -> RollingNoiseModel:
        """The site's noise model (built at the first use: its tables are not needed until then)."""
        if self._noise_model is None:
            self._noise_model = RollingNoiseModel(self.site, self._noise_cfg)
        return self._noise_model

    def consequences(self) -> Consequences:
        """The noise model and squeal parameters the advice weighs."""
        if self._consequences is None:
            self._consequences = Consequences(self.site, self.noise_model(), self._squeal_cfg)
        return self._consequences

    def _on_survey(self, msg: RoughnessSurvey) -> None:
        event = event_from_msg(msg)
        # Checked against the clock on arrival: one far-future survey would refuse every later one.
        if self.corrugation.take(event, self.stamp_ahead(event.stamp_ns)):
            self.state_services.publish_state()

    def _on_event(self, event: MaintenanceEvent, fit: KbPosterior | None, why: str) -> None:
        """A survey, grinding or indirect observation applied (checkpointed) or refused (logged)."""
        if why:
            self.get_logger().warning(f"roughness survey rejected: {why}")
            return
        if fit is not None and event.kind == surveys.KIND_SURVEY:
            self.get_logger().info(f"survey re-fitted K_b: P50 {self.est.k_b.tolist()}, "
                                   f"P10 {self.est.k_b_p10.tolist()}, P90 {self.est.k_b_p90.tolist()}")
        for made, outlook in self.corrugation.take_outlooks():
            self.sent.publish(self.outlook_pub, grinding_outlook_fields(made, outlook, self.site.site_id))
        self.state_services.save()

    def close(self) -> None:
        """The surveys and grinding later than every pass applied, and a final checkpoint (run_node
        calls it at shutdown)."""
        self.corrugation.finish()
        self.state_services.close()

    def diagnostic_values(self) -> dict[str, Any]:
        fc = self.est.forecast()
        values = {**super().diagnostic_values(), **self.counts, **self.corrugation.applied,
                  "applied late (passes after its stamp already counted)": self.corrugation.late,
                  "amplitude_worst_um": f"{1e6 * self.est.amplitude[fc.worst_band]:.3g}",
                  "days_to_threshold": f"{fc.days_to_threshold:.4g}",
                  "grinding_due": fc.grinding_due,
                  "state_age_s": f"{(time.time_ns() - self.est.newest_ns) / 1e9:.0f}" if self.est.newest_ns else "",
                  "last_grinding": format_iso_ns(self.est.last_grinding_ns) if self.est.last_grinding_ns else ""}
        values["surveys pending"] = len(self.corrugation.pending)
        values.update(self.state_services.diagnostic_values())
        if self.observer is not None:
            values.update({f"indirect {k}": v for k, v in sorted(self.observer.counts.items())})
        values.update({f"survey rejected: {why}": n for why, n in sorted(self.surveys_rejected.items())})
        return values

    def _level(self) -> tuple[int, str]:
        level, message = super()._level()
        if self.state_services.skipped and level == DiagnosticStatus.OK:
            return DiagnosticStatus.WARN, "resumed from the previous checkpoint (newest unreadable)"
        return level, message


def main(args: list[str] | None = None) -> int:
    return run_node(CorrugationEstimatorNode, args)


if __name__ == "__main__":
    sys.exit(main())
