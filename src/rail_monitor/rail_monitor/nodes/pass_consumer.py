"""Shared base of the nodes that take train_pass: the one place a pass is validated, rejections
counted and diagnostics published.

A malformed pass is rejected with its reason (:func:`rail_monitor.core.passes.rejection_reasons`),
counted per reason on /diagnostics, logged (throttled) and never reaches the model, so it leaves
any state untouched. A model raising on an accepted pass is a bug: it is counted and logged, the
node's diagnostics go to ERROR, and the node goes on with the next pass.

A callback takes the passes already queued behind its message too (at most ``max_batch``), and
the model handles each run of accepted passes in one vectorised call: a replay or a catch-up
costs a fraction per pass of what it costs one pass at a time; outputs and their order are the same.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import numpy as np
from diagnostic_msgs.msg import DiagnosticStatus
from rcl_interfaces.msg import SetParametersResult
from rclpy.parameter import Parameter

from rail_monitor.codec.cdr_columns import read_columns
from rail_monitor.codec.typestore import TRAIN_PASS
from rail_monitor.core.node_params import BATCH_SPECS, STAMP_SPECS, StampParams
from rail_monitor.core.params import ParamGroups, values_of
from rail_monitor.core.passes import PassTable, reject_ahead, rejection_reasons, with_class_defaults
from rail_monitor.core.timeutil import format_iso_ns
from rail_monitor.messages.fields import PassHead, passes_from_columns
from rail_monitor.nodes.base import (
    SITE_PARAMETERS,
    Diagnostics,
    RailNode,
    RateMeter,
    Sent,
    announce,
    declare,
    declare_site,
    isolate_failures,
    runs,
    subscribe_batched,
)
from rail_monitor.nodes.qos import STREAM_SUB_QOS
from rail_msgs.msg import TrainPass


class PassConsumerNode(RailNode):
    """Takes ``train_pass``; subclasses implement :meth:`on_passes` for accepted passes and call
    :meth:`listen` at the end of their ``__init__``, once their publishers exist: a node's outputs
    are visible in the graph before it takes its first pass (the pass source's start-up wait
    counts on it)."""

    PARAMETERS: ParamGroups = (*SITE_PARAMETERS, ("", BATCH_SPECS), ("stamps.", STAMP_SPECS))

    def __init__(self, name: str, **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        self.site = declare_site(self)
        self.taken = 0  # train_pass messages handled (the pass source's flow control reads it)
        self.accepted = RateMeter()
        self.rejected: Counter[str] = Counter()
        self.model_errors: Counter[str] = Counter()  # accepted passes a model raised on (a bug: ERROR)
        self.last_pass_ns = 0
        self.sent = Sent()  # messages published per topic (on /diagnostics: a soak checks the bag against it)
        self.margins = values_of(StampParams, declare(self, STAMP_SPECS, prefix="stamps."))
        self.stream_ns = 0  # newest pass taken: the reference of the stamp margin (a resumed state sets it)
        batch = declare(self, BATCH_SPECS)
        self.max_batch, self.log_throttle_s = batch["max_batch"], batch["log_throttle_s"]
        self.add_on_set_parameters_callback(self._on_set_throttle)
        Diagnostics(self, self.diagnostic_values, level=self._level)

    def listen(self) -> None:
        """Subscribe train_pass (the last step of a subclass's __init__), and say so."""
        # Raw: the TrainPasses taken are read from their CDR together, as columns (not converted by rclpy).
        subscribe_batched(self, TrainPass, "train_pass", self._on_train_passes, STREAM_SUB_QOS, self.max_batch,
                          raw=True)
        announce(self, site=self.site.site_id, radius_m=f"{self.site.curve_radius_m:g}",
                 classes="/".join(self.site.vehicles), **self.key_parameters())

    def key_parameters(self) -> dict[str, Any]:
        """What the start-up line states besides the site (subclasses)."""
        return {}

    def on_passes(self, table: PassTable, heads: list[PassHead]) -> None:
        """Handle consecutive accepted passes in order (table rows, class defaults filled, match
        heads: what outputs copy of their pass): one vectorised call, computing before it
        publishes. Nothing by default."""

    def on_validated(self, table: PassTable, reasons: list[str]) -> None:
        """See every taken pass with its reason ('' accepted), once, before on_passes. Nothing by default."""

    def _on_train_passes(self, raws: list[bytes]) -> None:
        try:
            read = read_columns(TRAIN_PASS, raws)
            for _, exc in read.refused:
                self._unreadable_pass(exc)
            if len(read):
                self._handle(*passes_from_columns(read.values))
        finally:
            self.taken += len(raws)  # after handling: a reader of ``taken`` sees the passes' effects

    def _handle(self, table: PassTable, heads: list[PassHead]) -> None:
        """Rejections and runs of accepted passes, in message order."""
        reasons = rejection_reasons(table, self.site)
        self.stream_ns = reject_ahead(table.stamp_ns, reasons, self.stream_ns, self.margins, self._live_clock_ns())
        reasons = reasons.tolist()
        self.on_validated(table, reasons)
        for run in runs(reasons, lambda a, b: not a and not b):
            why = reasons[run.start]
            if not why:
                self._accept(with_class_defaults(table.take(run), self.site), heads[run])
                continue
            self.rejected[why] += 1
            self.get_logger().warning(f"pass {heads[run.start].train_id!r} rejected: {why}",
                                      throttle_duration_sec=self.log_throttle_s)

    def _unreadable_pass(self, exc: Exception) -> None:
        self.rejected["not a readable TrainPass (CDR)"] += 1
        self.get_logger().warning(f"train_pass message refused: {exc}", throttle_duration_sec=self.log_throttle_s)

    def _on_set_throttle(self, params: list[Parameter]) -> SetParametersResult:
        """ros2 param set log_throttle_s: rclpy has checked its type and range already."""
        for p in params:
            if p.name == "log_throttle_s":
                self.log_throttle_s = float(p.value)
        return SetParametersResult(successful=True)

    def _live_clock_ns(self) -> int | None:
        """The node's clock [ns] when it is not on sim time (the stamp margin's second reference)."""
        return None if self.get_parameter("use_sim_time").value else self.get_clock().now().nanoseconds

    def stamp_ahead(self, stamp_ns: int) -> str:
        """Why an event stamp (a survey, a grinding) lies too far ahead of the passes taken or of
        the clock ('' when it does not), by the passes' margins; the stream reference stays."""
        reasons = np.array([""], dtype=object)
        reject_ahead(np.array([stamp_ns]), reasons, self.stream_ns, self.margins, self._live_clock_ns())
        return str(reasons[0])

    def _accept(self, table: PassTable, heads: list[PassHead]) -> None:
        self.accepted.tick(len(heads))
        self.last_pass_ns = heads[-1].stamp_ns
        # A model failing on one accepted pass must not stop the node, nor the other passes.
        isolate_failures(len(heads), lambda rows: self.on_passes(table.take(rows), heads[rows]),
                         lambda i, exc: self.model_error(f"pass {heads[i].train_id!r}", exc))

    def model_error(self, what: str, exc: Exception) -> None:
        """Count and log a model raising on accepted passes (what: which; diagnostics go to ERROR)."""
        why = f"{type(exc).__name__}: {(str(exc).splitlines() or [''])[0]}"
        self.model_errors[why] += 1
        self.get_logger().error(f"{what}: model error {why}", throttle_duration_sec=self.log_throttle_s)

    def diagnostic_values(self) -> dict[str, Any]:
        values: dict[str, Any] = {
            "taken": self.taken,
            "accepted": self.accepted.count,
            "rejected": sum(self.rejected.values()),
            "rate_per_s": f"{self.accepted.rate():.1f}",
            "last_pass": format_iso_ns(self.last_pass_ns) if self.last_pass_ns else "",
        }
        values.update({f"rejected: {reason}": n for reason, n in sorted(self.rejected.items())})
        values["model errors"] = sum(self.model_errors.values())
        values.update({f"model error: {why}": n for why, n in sorted(self.model_errors.items())})
        values.update({f"sent {topic}": n for topic, n in sorted(self.sent.items())})
        return values

    def _level(self) -> tuple[int, str]:
        if self.model_errors:
            return DiagnosticStatus.ERROR, f"{sum(self.model_errors.values())} pass(es) failed in a model"
        n = sum(self.rejected.values())
        if n:
            return DiagnosticStatus.WARN, f"{n} pass(es) rejected"
        return DiagnosticStatus.OK, "ok"
