"""alert_manager: raises and clears the site's WaysideAlerts from the model outputs.

Subscribes ``train_pass`` (rejected inputs), ``noise/squeal``, ``noise/rolling``,
``corrugation/state`` (every state, in order) and ``noise/measured`` (rail_msgs/MeasuredPassNoise:
each measurement is paired with its pass's predictions, which this node takes anyway, and its
residuals are published on ``noise/residual``, rail_msgs/NoiseResidual, and raise the wheel-defect
and drift alerts; rail_monitor.measured) and ``noise/squeal_calibration`` (each fit of the squeal
model: the squeal-drift alert per friction state); publishes each raise and clear on ``alerts``
(rail_msgs/WaysideAlert; reliable, transient local, depth 1000) and the standing set on
``alerts/standing`` (rail_msgs/WaysideAlertArray; latched), so a late subscriber sees the
standing alerts at once. Thresholds and hysteresis: ``alerts.*``
(:data:`rail_monitor.alerts.config.ALERT_SPECS`) and the corrugation lead time
``corrugation.lead_time_days``.
"""

from __future__ import annotations

import sys
from collections import Counter, deque
from collections.abc import Callable
from typing import Any

import numpy as np
from diagnostic_msgs.msg import DiagnosticStatus
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter

from rail_monitor.alerts.config import ALERT_SPECS, KIND_NAMES, NOISE_METRICS, SEVERITY_CRITICAL, alert_config
from rail_monitor.alerts.manager import Alert, AlertManager, describe
from rail_monitor.codec.cdr_columns import read_columns
from rail_monitor.core.errors import ConfigError
from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.config import LEAD_TIME
from rail_monitor.measured.config import RESIDUAL_SPECS, residual_config
from rail_monitor.measured.residuals import Predicted, Residual, ResidualTracker
from rail_monitor.messages.fields import (
    measurement_from_msg,
    noise_residual_fields,
    time_columns_ns,
    time_ns,
    wayside_alert_array_fields,
    wayside_alert_fields,
)
from rail_monitor.messages.output_columns import (
    band_runs,
    corrugation_series,
    noise_refusals,
    predictions,
    squeal_refusals,
    state_refusals,
)
from rail_monitor.messages.topics import GRAPH_TOPICS
from rail_monitor.nodes.base import declare, subscribe_batched, take_queued, wall_timer
from rail_monitor.nodes.pass_consumer import PassConsumerNode
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import ALERT_QOS, LATEST_QOS, STATE_SUB_QOS, STREAM_QOS, STREAM_SUB_QOS
from rail_monitor.noise.config import PREDICTED_SPECS, band_centres_hz, selected_models
from rail_msgs.msg import (
    CorrugationState,
    MeasuredPassNoise,
    NoiseResidual,
    RollingNoise,
    SquealCalibration,
    SquealPrediction,
    WaysideAlert,
    WaysideAlertArray,
)

RECENT_KEPT = 100  # events the node keeps after publishing them, to inspect a running node


class AlertManagerNode(PassConsumerNode):
    EXECUTABLE = "alert_manager"
    PARAMETERS = (*PassConsumerNode.PARAMETERS, ("corrugation.", (LEAD_TIME,)), ("alerts.", ALERT_SPECS),
                  ("residual.", RESIDUAL_SPECS), ("noise.", PREDICTED_SPECS))

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("alert_manager", **kwargs)
        self._lead = declare(self, (LEAD_TIME,), prefix="corrugation.")["lead_time_days"]
        self.recent: deque[Alert] = deque(maxlen=RECENT_KEPT)  # the latest events published
        self.alerts = AlertManager(alert_config(declare(self, ALERT_SPECS, prefix="alerts."), self._lead, prefix=""))
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.inputs: Counter[str] = Counter()
        self.pub = self.create_publisher(WaysideAlert, "alerts", ALERT_QOS)
        self.standing_pub = self.create_publisher(WaysideAlertArray, "alerts/standing", LATEST_QOS)
        noise = declare(self, PREDICTED_SPECS, prefix="noise.")
        self.tracker = ResidualTracker(residual_config(declare(self, RESIDUAL_SPECS, prefix="residual."), prefix=""),
                                       band_centres_hz(), (noise["receiver_distance_m"], noise["receiver_height_m"]),
                                       selected_models(noise["model"]))
        self.residual_pub = self.create_publisher(NoiseResidual, "noise/residual", STREAM_QOS)
        self.measured_sub = subscribe_batched(self, MeasuredPassNoise, "noise/measured", self._on_measured,
                                              STREAM_SUB_QOS, self.max_batch)
        subscribe_batched(self, SquealCalibration, "noise/squeal_calibration", self._on_squeal_fits, STREAM_SUB_QOS,
                          self.max_batch)
        # Each stream in its own order (streams do not interact): what is queued is taken at once and
        # fed as one series; alerts/standing (latched, latest only) is published once per series.
        # Raw: the messages taken are read from their CDR together, as columns (not converted by rclpy).
        for msg_type, topic, handle, qos in ((SquealPrediction, "noise/squeal", self._on_squeal, STREAM_SUB_QOS),
                                             (RollingNoise, "noise/rolling", self._on_noise, STREAM_SUB_QOS),
                                             (CorrugationState, "corrugation/state", self._on_states, STATE_SUB_QOS)):
            subscribe_batched(self, msg_type, topic, handle, qos, self.max_batch, raw=True)
        # The initial (empty) standing set for late subscribers, once the clock runs: a message
        # stamped 0 before the first /clock would stretch a bag's timeline back to 1970.
        self._initial = wall_timer(self, 0.1, self._publish_initial_standing)
        self.listen()

    def key_parameters(self) -> dict[str, Any]:
        c = self.alerts.cfg
        return {"noise": f"{c.noise_metric}>{c.noise_limit_dba:g} dB(A)", "squeal_window": c.squeal_window_passes}

    def on_validated(self, table: PassTable, reasons: list[str]) -> None:
        self._emit(self.alerts.on_train_passes(table.stamp_ns, np.array([bool(r) for r in reasons])))

    def _usable(self, topic: str, raws: list[bytes], refusals: Callable[[Any], np.ndarray]) -> tuple[Any, np.ndarray]:
        """The messages of topic as columns, and the rows of those this node can use; the others
        counted by reason and logged."""
        read = read_columns(GRAPH_TOPICS[topic][0], raws)
        for _, exc in read.refused:
            self._unreadable_on(topic, exc)
        reasons = refusals(read.values)
        self.inputs[topic] += len(reasons)
        for why in reasons[reasons != ""].tolist():
            self._refuse(topic, why)
        return read.values, np.flatnonzero(reasons == "")

    def _refuse(self, topic: str, why: str) -> None:
        self.inputs[f"{topic} refused: {why}"] += 1
        self.get_logger().warning(f"{topic} message refused: {why}", throttle_duration_sec=self.log_throttle_s)

    def _unreadable_on(self, topic: str, exc: Exception) -> None:
        self.inputs[topic] += 1
        self._refuse(topic, f"not a readable CDR message ({exc})")

    def _on_squeal(self, raws: list[bytes]) -> None:
        values, ok = self._usable("noise/squeal", raws, squeal_refusals)
        if len(ok):
            stamps = time_columns_ns(values.header.stamp)
            self._emit(self.alerts.on_squeal(stamps[ok], values.risk[ok].astype(np.int64)))
            self._predicted(predictions(values, ok))

    def _on_noise(self, raws: list[bytes]) -> None:
        values, ok = self._usable("noise/rolling", raws, noise_refusals)
        stamps, model_of = time_columns_ns(values.header.stamp), np.array(values.model, object)
        events: list[Alert] = []
        for model in dict.fromkeys(model_of[ok].tolist()):  # each source model's stream in its order
            mine = ok[model_of[ok] == model]
            events += self.alerts.on_noise(stamps[mine], model, {
                k: np.asarray(getattr(values, k), float)[mine] for k in NOISE_METRICS})
        self._emit(sorted(events, key=lambda e: e.stamp_ns))
        self._predicted(predictions(values, ok))

    def _predicted(self, predicted: list[Predicted]) -> None:
        """Predictions for the measurements. Measurements sent before these passes are queued by
        now (a replay sends each before the next pass, acknowledged): they are taken first, so
        they are scored in stamp order."""
        queued = take_queued(self.measured_sub, self.max_batch)
        if queued:
            self._on_measured(queued)
        self._residuals(self.tracker.add_predictions(predicted))

    def _on_measured(self, msgs: list[MeasuredPassNoise]) -> None:
        self.inputs["noise/measured"] += len(msgs)
        before = sum(self.tracker.refused.values())
        self._residuals([r for m in msgs for r in self.tracker.add_measurement(measurement_from_msg(m))])
        if sum(self.tracker.refused.values()) > before:
            self.get_logger().warning(f"noise/measured refused: {dict(self.tracker.refused)}",
                                      throttle_duration_sec=self.log_throttle_s)

    def _on_squeal_fits(self, msgs: list[SquealCalibration]) -> None:
        topic = "noise/squeal_calibration"
        for m in msgs:
            self.inputs[topic] += 1
            why = squeal_fit_refusal(m)
            if why:
                self._refuse(topic, why)
                continue
            windows = zip(m.friction_state, m.window_passes, m.window_squealing, m.window_share_p10,
                          m.window_share_p90, strict=True)
            self._emit(self.alerts.on_squeal_fit(time_ns(m.header.stamp), [w for w in windows if w[1]]))

    def _residuals(self, residuals: list[Residual]) -> None:
        for r in residuals:
            self.sent.publish(self.residual_pub, noise_residual_fields(r, self.site.site_id))
        if residuals:
            self._emit(self.alerts.on_residuals(residuals))

    def _on_states(self, raws: list[bytes]) -> None:
        values, ok = self._usable("corrugation/state", raws, state_refusals)
        for run in band_runs(values, ok):  # one series per bands and thresholds
            self._emit(self.alerts.on_states(**corrugation_series(values, run)))

    def _on_set_parameters(self, params: list[Parameter]) -> SetParametersResult:
        return retune_alerts(self, self.alerts, self._lead, params)

    def _publish_initial_standing(self) -> None:
        now = self.get_clock().now().nanoseconds
        if self.sent[self.standing_pub.topic_name] or now > 0:  # an alert published it already, or the clock runs
            self._initial.cancel()
            if not self.sent[self.standing_pub.topic_name]:
                self._publish_standing(now)

    def _emit(self, events: list[Alert]) -> None:
        self.alerts.take_events()  # published here: the manager keeps none over a run of years
        self.recent.extend(events)
        for e in events:
            self.sent.publish(self.pub, wayside_alert_fields(e, self.site.site_id))
            self.get_logger().info(describe(e))
        if events:
            self._publish_standing(events[-1].stamp_ns)

    def _publish_standing(self, stamp_ns: int) -> None:
        alerts = sorted(self.alerts.standing.values(), key=lambda a: (a.kind, a.key))
        self.sent.publish(self.standing_pub, wayside_alert_array_fields(alerts, stamp_ns, self.site.site_id))

    def diagnostic_values(self) -> dict[str, Any]:
        return {**super().diagnostic_values(), **{f"taken {k}": n for k, n in sorted(self.inputs.items())},
                "standing": len(self.alerts.standing), "raised": self.alerts.raised,
                "cleared": self.alerts.cleared, "residuals": self.sent[self.residual_pub.topic_name],
                "measurements scored late": self.tracker.late,
                **{f"noise/measured refused: {why}": n for why, n in sorted(self.tracker.refused.items())},
                **{f"standing {KIND_NAMES[k]}": n for k, n in
                   sorted(Counter(kind for kind, _ in self.alerts.standing).items())}}

    def _level(self) -> tuple[int, str]:
        if any(a.severity >= SEVERITY_CRITICAL for a in self.alerts.standing.values()):
            return DiagnosticStatus.ERROR, f"{len(self.alerts.standing)} alert(s) standing, critical among them"
        if self.alerts.standing:
            return DiagnosticStatus.WARN, f"{len(self.alerts.standing)} alert(s) standing"
        return super()._level()


def squeal_fit_refusal(m: SquealCalibration) -> str:
    """Why a SquealCalibration cannot be judged for drift ('' if it can)."""
    if len({len(getattr(m, f)) for f in ("friction_state", "window_passes", "window_squealing", "window_share_p10",
                                         "window_share_p90")}) != 1:
        return "its friction states and window arrays differ in length"
    if any(k > p for p, k in zip(m.window_passes, m.window_squealing, strict=True)):
        return "more squealing passes than passes in its window"
    if not all(0.0 <= lo <= hi <= 1.0 for p, lo, hi in zip(m.window_passes, m.window_share_p10, m.window_share_p90,
                                                           strict=True) if p):
        return "a predicted share outside [0, 1], or its P10 above its P90"
    return ""


def retune_alerts(node: Node, alerts: AlertManager, lead_time_days: float,
                  params: list[Parameter]) -> SetParametersResult:
    """ros2 param set on alerts.*: checked as at start-up (ranges, hysteresis), then applied to
    the next inputs; a refusal gives the reason and changes nothing."""
    mine = {p.name[len("alerts."):]: p.value for p in params if p.name.startswith("alerts.")}
    if not mine:
        return SetParametersResult(successful=True)
    current = {s.name: node.get_parameter(f"alerts.{s.name}").value for s in ALERT_SPECS}
    try:
        cfg = alert_config({**current, **mine}, lead_time_days, prefix="")
    except ConfigError as exc:
        return SetParametersResult(successful=False, reason=str(exc))
    alerts.retune(cfg)
    node.get_logger().info("alerts retuned: " + ", ".join(f"alerts.{k}={v!r}" for k, v in sorted(mine.items())))
    return SetParametersResult(successful=True)


def main(args: list[str] | None = None) -> int:
    return run_node(AlertManagerNode, args)


if __name__ == "__main__":
    sys.exit(main())
