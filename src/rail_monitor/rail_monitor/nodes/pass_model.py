"""Shared base of the model nodes: take train_pass, validate, count rejections, diagnose.

A malformed pass is rejected with its reason (rail_monitor.passes.rejection_reasons), counted
per reason on /diagnostics, logged (throttled) and never reaches the model, so it leaves any
state untouched. A model raising on an accepted pass is a bug: it is counted and logged, the
node's diagnostics go to ERROR, and the node goes on with the next pass.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus
from rclpy.node import Node

from rail_monitor.nodes.base import Diagnostics, RateMeter, declare_site
from rail_monitor.nodes.convert import time_ns, train_pass_row
from rail_monitor.nodes.qos import STREAM_SUB_QOS
from rail_monitor.passes import PassTable, rejection_reasons, with_class_defaults
from rail_monitor.timeutil import format_iso_ns
from rail_msgs.msg import TrainPass


class PassModelNode(Node):
    """Subscribes ``train_pass``; subclasses implement :meth:`on_pass` for accepted passes."""

    def __init__(self, name: str, **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        self.site = declare_site(self)
        self.taken = 0  # train_pass messages handled (the pass source's flow control reads it)
        self.accepted = RateMeter()
        self.rejected: Counter[str] = Counter()
        self.model_errors: Counter[str] = Counter()  # accepted passes a model raised on (a bug: ERROR)
        self.last_pass_ns = 0
        self.create_subscription(TrainPass, "train_pass", self._on_train_pass, STREAM_SUB_QOS)
        Diagnostics(self, self.diagnostic_values, level=self._level)

    def on_pass(self, table: PassTable, msg: TrainPass) -> None:
        """Handle one accepted pass: a one-row table with class defaults filled, and its message."""
        raise NotImplementedError

    def on_rejected(self, msg: TrainPass, reason: str) -> None:
        """Handle one rejected pass (after it is counted); nothing by default."""

    def _on_train_pass(self, msg: TrainPass) -> None:
        try:
            self._handle(msg)
        finally:
            self.taken += 1  # after handling: a reader of ``taken`` sees the pass's effects

    def _handle(self, msg: TrainPass) -> None:
        table = PassTable.from_rows([train_pass_row(msg)])
        reason = rejection_reasons(table, self.site)[0]
        if reason:
            self.rejected[reason] += 1
            self.get_logger().warning(f"pass {msg.train_id!r} rejected: {reason}", throttle_duration_sec=5.0)
            self.on_rejected(msg, reason)
            return
        self.accepted.tick()
        self.last_pass_ns = time_ns(msg.header.stamp)
        try:
            self.on_pass(with_class_defaults(table, self.site), msg)
        except Exception as exc:  # a model failing on one accepted pass must not stop the node
            why = f"{type(exc).__name__}: {(str(exc).splitlines() or [''])[0]}"
            self.model_errors[why] += 1
            self.get_logger().error(f"pass {msg.train_id!r}: model error {why}", throttle_duration_sec=5.0)

    def diagnostic_values(self) -> dict[str, Any]:
        values: dict[str, Any] = {
            "accepted": self.accepted.count,
            "rejected": sum(self.rejected.values()),
            "rate_per_s": f"{self.accepted.rate():.1f}",
            "last_pass": format_iso_ns(self.last_pass_ns) if self.last_pass_ns else "",
        }
        values.update({f"rejected: {reason}": n for reason, n in sorted(self.rejected.items())})
        values["model errors"] = sum(self.model_errors.values())
        values.update({f"model error: {why}": n for why, n in sorted(self.model_errors.items())})
        return values

    def _level(self) -> tuple[int, str]:
        if self.model_errors:
            return DiagnosticStatus.ERROR, f"{sum(self.model_errors.values())} pass(es) failed in a model"
        n = sum(self.rejected.values())
        if n:
            return DiagnosticStatus.WARN, f"{n} pass(es) rejected"
        return DiagnosticStatus.OK, "ok"
