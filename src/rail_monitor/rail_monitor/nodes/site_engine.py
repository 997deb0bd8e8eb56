"""site_engine: every model of a site in one node, the site engine (rail_monitor.engine.site) behind
it, the same code batch mode runs.

Subscribes ``train_pass`` (a callback's backlog is read from its CDR once, as columns, and fed to
the engine as one chunk: it validates each pass, counts it, predicts its squeal and its rolling
noise on the state that includes it and updates the alert windows), ``roughness_survey`` (a survey
re-fits K_b, a grinding resets the state: each applied before the first pass stamped later than
it) and ``noise/measured`` (paired with its pass's predictions: residuals, the wheel-defect and
drift alerts, and with ``residual.indirect_days`` > 0 the indirect roughness windows).

Publishes what the four model nodes of the separate-process layout publish, on the same topics
with the same QoS: ``noise/squeal``, ``corrugation/state`` (every counted pass, or at most every
``state_period_s``), ``noise/rolling``, ``alerts`` and ``alerts/standing``, ``noise/residual``,
``corrugation/indirect_roughness``, ``grinding/outlook`` (rail_msgs/GrindingOutlook, on each survey,
grinding or indirect observation applied: the input of grinding_planner) and ``speed_advisory``
(every ``advisory_period_s``). Serves
``evaluate_speed_distribution``; checkpoints the state as corrugation_estimator does
(``checkpoint_path``). A pass older than one already taken is rejected with its reason (the engine
takes passes in stamp order). Parameters: the site file's ``/**`` section and ``/**/site_engine``.
"""

from __future__ import annotations

import sys
from collections import Counter
from dataclasses import asdict
from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus
from rcl_interfaces.msg import SetParametersResult
from rclpy.parameter import Parameter

from rail_monitor.advice.consequences import Consequences
from rail_monitor.alerts.config import ALERT_SPECS, SEVERITY_CRITICAL
from rail_monitor.alerts.manager import Alert, describe
from rail_monitor.codec.cdr_columns import read_columns
from rail_monitor.codec.typestore import TRAIN_PASS
from rail_monitor.core.node_params import ESTIMATOR_SPECS, EstimatorParams
from rail_monitor.core.params import values_of
from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.config import CORRUGATION_SPECS
from rail_monitor.economics.config import ECONOMICS_SPECS
from rail_monitor.engine.site import SiteEngine
from rail_monitor.measured.config import RESIDUAL_SPECS
from rail_monitor.measured.records import Measurement
from rail_monitor.measured.residuals import Residual
from rail_monitor.messages import outputs
from rail_monitor.messages.event_fields import event_from_msg
from rail_monitor.messages.fields import (
    measurement_from_msg,
    passes_from_columns,
    wayside_alert_array_fields,
)
from rail_monitor.nodes.alert_manager import retune_alerts
from rail_monitor.nodes.base import declare, declare_site_values, subscribe_batched, take_queued, wall_timer
from rail_monitor.nodes.convert import output_publishers
from rail_monitor.nodes.pass_consumer import PassConsumerNode
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import EVENT_QOS, STREAM_SUB_QOS
from rail_monitor.nodes.state_services import StateServices
from rail_monitor.noise.config import NOISE_SPECS
from rail_monitor.squeal.config import SQUEAL_SPECS
from rail_msgs.msg import MeasuredPassNoise, RoughnessSurvey

MODEL_SECTIONS = (("corrugation.", CORRUGATION_SPECS), ("noise.", NOISE_SPECS), ("squeal.", SQUEAL_SPECS),
                  ("economics.", ECONOMICS_SPECS),
                  ("residual.", RESIDUAL_SPECS), ("alerts.", ALERT_SPECS))
PUBLISHED = ("noise/squeal", "corrugation/state", "noise/rolling", "alerts", "alerts/standing", "noise/residual",
             "corrugation/indirect_roughness", "noise/squeal_calibration", "grinding/outlook")


class SiteEngineNode(PassConsumerNode):
    EXECUTABLE = "site_engine"
    PARAMETERS = (*PassConsumerNode.PARAMETERS, ("", ESTIMATOR_SPECS), *MODEL_SECTIONS)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("site_engine", **kwargs)
        self.params = values_of(EstimatorParams, declare(self, ESTIMATOR_SPECS))
        values = declare_site_values(self)
        for prefix, specs in MODEL_SECTIONS:
            values.update({prefix + k: v for k, v in declare(self, specs, prefix=prefix).items()})
        values.update({f"stamps.{k}": v for k, v in asdict(self.margins).items()})
        # numpy kernels (numba's import stays out of a live start-up); one thread: the executor's.
        self.engine = SiteEngine(values, threads=1, engine="numpy")
        self.engine.measured_live = True  # a station's measurement comes after its pass
        # The indirect roughness only where its windows are kept (as corrugation_estimator offers it),
        # the squeal model's fits where it is fitted.
        offered = {"corrugation/indirect_roughness": self.engine.observer is not None,
                   "noise/squeal_calibration": self.engine.squeal.enabled}
        self.pubs = output_publishers(self, tuple(t for t in PUBLISHED if offered.get(t, True)))
        self.state_services = StateServices(self, self.engine.estimator, self.params, self.consequences, self.sent,
                                            self.pubs["corrugation/state"], self.engine.observer, self.engine.squeal)
        self.state_services.resume(self.engine.resume)
        self.stream_ns = self.engine.estimator.newest_ns
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.alert_stream = outputs.AlertStream(self.site.site_id)
        self.counts: Counter[str] = Counter()
        self._events_seen = (0, 0)  # (applied, refused) already logged and checkpointed
        self.survey_sub = self.create_subscription(RoughnessSurvey, "roughness_survey", self._on_survey, EVENT_QOS)
        self.measured_sub = subscribe_batched(self, MeasuredPassNoise, "noise/measured", self._on_measured,
                                              STREAM_SUB_QOS, self.max_batch)
        # The initial (empty) standing set for late subscribers, once the clock runs (as alert_manager).
        self._initial = wall_timer(self, 0.1, self._publish_initial_standing)
        self.listen()

    def key_parameters(self) -> dict[str, Any]:
        est = self.engine.estimator
        return {"checkpoint": self.state_services.path or "none", "passes": est.total_pass_count,
                "models": "+".join(self.engine.model.models), "lead_time_days": f"{est.cfg.lead_time_days:g}"}

    def consequences(self) -> Consequences:
        """The noise model and squeal parameters the advice weighs (the engine's)."""
        return self.engine.consequences()

    def publish_advisory(self) -> None:
        """The advice on the current state (also every advisory_period_s)."""
        self.state_services.publish_advisory()

    def _on_train_passes(self, raws: list[bytes]) -> None:
        # Surveys and measurements sent before these passes are queued by now (a replay sends each
        # before the first later pass, acknowledged): taken first, so they wait for the right pass.
        for msg in take_queued(self.survey_sub, 1000):
            self._on_survey(msg)
        self._take_measured(take_queued(self.measured_sub, self.max_batch))
        try:
            read = read_columns(TRAIN_PASS, raws)
            for _, exc in read.refused:
                self._unreadable_pass(exc)
            if len(read):
                self._feed(passes_from_columns(read.values)[0])
        finally:
            self.taken += len(raws)  # after handling: a reader of ``taken`` sees the passes' effects

    def _feed(self, table: PassTable) -> None:
        try:
            result = self.engine.feed(table, late=True, clock_ns=self._live_clock_ns())
        except Exception as exc:  # a bug in a model: counted and logged, the node goes on
            self.model_error(f"{len(table)} pass(es)", exc)
            return
        reasons = result.reasons
        # What a pass source would not have sent (a stamp no Time holds, or far ahead of its stream)
        # is left out before the models; here it came anyway: a rejection like any other.
        for why, n in (Counter(reasons[reasons != ""].tolist()) + Counter(result.left_out)).items():
            self.rejected[why] += n
            self.get_logger().warning(f"{n} pass(es) rejected: {why}", throttle_duration_sec=self.log_throttle_s)
        if len(result.accepted):
            self.accepted.tick(len(result.accepted))
            self.last_pass_ns = int(result.accepted.stamp_ns[-1])
        self.counts["counted"] += len(result.trajectory)
        self.state_services.counted(len(result.trajectory))
        for msgs in outputs.per_pass(result, self.site.site_id):
            if msgs.topic != "corrugation/state" or self.params.state_period_s == 0.0:
                self._send(msgs)
            elif msgs.datas:
                self.state_services.publish_state_if_due()
        self._send(outputs.outlooks(result.outlooks, self.site.site_id))
        self._events()
        self._publish(result.alerts, result.residuals, result.observations, result.calibrations)
        self._settle()

    def _send(self, msgs: outputs.Messages) -> None:
        pub = self.pubs[msgs.topic]
        for data in msgs.datas:
            self.sent.send(pub, data)

    def _publish(self, alerts: list[Alert], residuals: list[Residual], observations: list[Any],
                 calibrations: list[Any] = ()) -> None:
        for msgs in outputs.measured(residuals, observations, self.site.site_id, calibrations):
            self._send(msgs)
        for msgs in self.alert_stream.messages(alerts):
            self._send(msgs)
        for a in alerts:
            self.get_logger().info(describe(a))

    def _settle(self) -> None:
        """What needs no later pass: the measurements of passes taken, and every alert event."""
        _, residuals, alerts = self.engine.settle()
        self._publish(alerts, residuals, [])

    def _take_measured(self, msgs: list[MeasuredPassNoise]) -> list[Measurement]:
        taken = [measurement_from_msg(m) for m in msgs]
        self.counts["measurements taken"] += len(taken)
        self.engine.take_measurements(taken)
        return taken

    def _on_measured(self, msgs: list[MeasuredPassNoise]) -> None:
        if self._take_measured(msgs):
            self._settle()

    def _on_survey(self, msg: RoughnessSurvey) -> None:
        event = event_from_msg(msg)
        if self.engine.corrugation.take(event, self.stamp_ahead(event.stamp_ns)):
            self.state_services.publish_state()
        self._events()

    def _events(self) -> None:
        """Surveys and grinding applied since the last look: checkpointed; refused: logged."""
        corr = self.engine.corrugation
        self._send(outputs.outlooks(corr.take_outlooks(), self.site.site_id))  # those applied on arrival
        applied, refused = sum(corr.applied.values()), sum(corr.refused.values())
        if refused > self._events_seen[1]:
            self.get_logger().warning(f"roughness survey rejected: {dict(corr.refused)}")
        if applied > self._events_seen[0]:
            self.state_services.save()
        self._events_seen = (applied, refused)

    def _publish_initial_standing(self) -> None:
        now = self.get_clock().now().nanoseconds
        standing = self.pubs["alerts/standing"]
        if self.sent[standing.topic_name] or now > 0:  # an alert published it already, or the clock runs
            self._initial.cancel()
            if not self.sent[standing.topic_name]:
                self._send(outputs.one("alerts/standing", wayside_alert_array_fields([], now, self.site.site_id), now))

    def _on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        lead = self.engine.estimator.cfg.lead_time_days
        return retune_alerts(self, self.engine.alerts, lead, params)

    def close(self) -> None:
        """The surveys and grinding later than every pass applied, and a final checkpoint (run_node
        calls it at shutdown)."""
        self.engine.corrugation.finish()
        self._events()
        self.state_services.close()

    def diagnostic_values(self) -> dict[str, Any]:
        e = self.engine
        fc = e.estimator.forecast()
        values = {**super().diagnostic_values(), **self.counts, **e.corrugation.applied,
                  "applied late (passes after its stamp already counted)": e.corrugation.late,
                  "days_to_threshold": f"{fc.days_to_threshold:.4g}", "grinding_due": fc.grinding_due,
                  "surveys pending": len(e.corrugation.pending), "standing": len(e.alerts.standing),
                  "raised": e.alerts.raised, "cleared": e.alerts.cleared,
                  "measurements scored late": e.tracker.late, **self.state_services.diagnostic_values(),
                  **{f"squeal fit {k}": v for k, v in sorted(e.squeal.counts.items())}}
        values.update({f"survey rejected: {why}": n for why, n in sorted(e.corrugation.refused.items())})
        values.update({f"noise/measured refused: {why}": n for why, n in sorted(e.tracker.refused.items())})
        if e.observer is not None:
            values.update({f"indirect {k}": v for k, v in sorted(e.observer.counts.items())})
        return values

    def _level(self) -> tuple[int, str]:
        standing = self.engine.alerts.standing
        if any(a.severity >= SEVERITY_CRITICAL for a in standing.values()):
            return DiagnosticStatus.ERROR, f"{len(standing)} alert(s) standing, critical among them"
        level, message = super()._level()
        if level == DiagnosticStatus.OK and standing:
            return DiagnosticStatus.WARN, f"{len(standing)} alert(s) standing"
        return level, message


def main(args: list[str] | None = None) -> int:
    return run_node(SiteEngineNode, args)


if __name__ == "__main__":
    sys.exit(main())
