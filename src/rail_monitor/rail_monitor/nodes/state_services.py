"""What a node holding a site's corrugation state offers besides its per-pass outputs: the whole
state now (after a survey or grinding, or every ``state_period_s``), the speed advisory (latched,
every ``advisory_period_s``), the ``evaluate_speed_distribution`` service, and the checkpoint
(written by a thread of its own, rail_monitor.engine.checkpoint.CheckpointWriter).
corrugation_estimator and site_engine hold one each.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from rail_monitor.advice import growth, plan
from rail_monitor.advice.consequences import Consequences
from rail_monitor.core.node_params import EstimatorParams
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.engine import checkpoint
from rail_monitor.engine.squeal_site import SquealSite
from rail_monitor.measured.observer import IndirectObserver
from rail_monitor.messages.fields import corrugation_state_fields, speed_advisory_fields
from rail_monitor.nodes.base import RailNode, Sent, wall_timer
from rail_monitor.nodes.qos import LATEST_QOS
from rail_msgs.msg import SpeedAdvisory
from rail_msgs.srv import EvaluateSpeedDistribution

CLOSE_TIMEOUT_S = 30.0  # the last checkpoint's write at shutdown (a year kept: about 0.1 s)


class StateServices:
    """The whole state, the advisory, the service and the checkpoint of the state ``est`` held by ``node``.

    consequences: the noise model and squeal parameters the advice weighs (built at first use);
    state_pub: the node's corrugation/state publisher; observer, squeal: the indirect roughness
    windows and the squeal model's fit checkpointed with the state (None: none).
    """

    def __init__(self, node: RailNode, est: CorrugationEstimator, params: EstimatorParams,
                 consequences: Callable[[], Consequences], sent: Sent, state_pub: Any,
                 observer: IndirectObserver | None = None, squeal: SquealSite | None = None) -> None:
        self.node, self.est, self.params, self.sent, self.state_pub = node, est, params, sent, state_pub
        self._last_state_t = float("-inf")  # time.monotonic() of the last periodic state [s]
        self.observer, self.squeal = observer, squeal
        self._consequences = consequences
        self.path = params.checkpoint_path
        self.skipped: list[str] = []
        self.writer = checkpoint.CheckpointWriter(self.path, on_error=self._failed) if self.path else None
        self.since_checkpoint = 0
        self.advisory_pub = node.create_publisher(SpeedAdvisory, "speed_advisory", LATEST_QOS)
        node.create_service(EvaluateSpeedDistribution, "evaluate_speed_distribution", self._on_evaluate)
        wall_timer(node, params.advisory_period_s, self.publish_advisory)

    def resume(self, load: Callable[[str], tuple[Any, list[str]]]) -> None:
        """Resume from the checkpoint by load(path) (an unreadable one falls back to the previous;
        none readable is a ConfigError: no silent fresh start), and log it."""
        if not self.path:
            return
        used, self.skipped = load(self.path)
        for why in self.skipped:
            self.node.get_logger().error(f"checkpoint skipped: {why}")
        if used is not None:
            self.node.get_logger().info(f"resumed from {used}: {self.est.total_pass_count} passes")

    def counted(self, n: int) -> None:
        """n passes counted: a checkpoint once checkpoint_every_passes have been since the last."""
        self.since_checkpoint += n
        if self.since_checkpoint >= self.params.checkpoint_every_passes:
            self.save()

    def publish_state(self) -> None:
        """The whole state and its forecast, now."""
        self.sent.publish(self.state_pub, corrugation_state_fields(self.est, self.est.forecast(),
                                                                   self.node.site.site_id))

    def publish_state_if_due(self) -> None:
        """The whole state now if state_period_s [s] of wall time have passed since the last
        (state_period_s > 0: the nodes publish it at most that often, not per pass)."""
        now = time.monotonic()
        if now - self._last_state_t >= self.params.state_period_s:
            self.publish_state()
            self._last_state_t = now

    def save(self) -> None:
        """Copy the state here; the writer's thread encodes and writes it (the passes behind wait
        only for the copy)."""
        if self.writer is None:
            return
        self.writer.submit(checkpoint.snapshot(self.est, self.observer, self.squeal))
        self.since_checkpoint = 0

    def _failed(self, exc: OSError) -> None:  # on the writer's thread
        self.node.get_logger().error(f"checkpoint to {self.path} failed: {exc}", throttle_duration_sec=60.0)

    def close(self) -> None:
        """The final checkpoint (at shutdown, after the last events are applied)."""
        if self.since_checkpoint:
            self.save()
        if self.writer is not None and not self.writer.close(CLOSE_TIMEOUT_S):
            self.node.get_logger().error(f"checkpoint to {self.path} not written within {CLOSE_TIMEOUT_S:g} s")

    def publish_advisory(self) -> None:
        if not len(self.est.kept):
            return
        try:
            advised = plan.advise(self.est, self._consequences())
        except ValueError as exc:
            self.node.get_logger().warning(f"no speed advice: {exc}", throttle_duration_sec=60.0)
            return
        self.sent.publish(self.advisory_pub, speed_advisory_fields(advised, self.est.newest_ns,
                                                                   self.node.site.site_id))

    def _on_evaluate(self, req: EvaluateSpeedDistribution.Request,
                     res: EvaluateSpeedDistribution.Response) -> EvaluateSpeedDistribution.Response:
        try:
            ev = growth.evaluate(self.est, req.speed_mps, req.probability, req.friction_state, req.passes_per_day)
            side = plan.evaluate_consequences(self.est, self._consequences(), req.speed_mps, req.probability)
        except ValueError as exc:
            res.success, res.message = False, str(exc)
            return res
        res.noise_model, res.noise_change_dba = side.noise_model, side.noise_change_dba.tolist()
        res.squeal_share_current, res.squeal_share = side.squeal_share_current, side.squeal_share
        res.success = True
        res.wavelength_m = self.est.bands.tolist()
        res.growth_per_axle_pass = ev.growth_per_axle_pass.tolist()
        res.peak_growth, res.peak_wavelength_m = ev.peak_growth, ev.peak_wavelength_m
        res.grinding_interval_factor, res.days_to_threshold = ev.grinding_interval_factor, ev.days_to_threshold
        return res

    def diagnostic_values(self) -> dict[str, Any]:
        values: dict[str, Any] = {}
        if self.writer is not None:
            values.update({"checkpoints": self.writer.written, "checkpoint failures": self.writer.failed,
                           "checkpoints coalesced": self.writer.coalesced})
        values.update({f"checkpoint skipped {i + 1}": why for i, why in enumerate(self.skipped)})
        return values
