"""rolling_noise_predictor: predicted rolling noise at the site's receiver for every accepted train pass.

Subscribes ``train_pass`` and ``corrugation/state`` (every state, in order); publishes
``noise/rolling`` (rail_msgs/RollingNoise) per pass, one message per source model: ``noise.model``
is cnossos, mechanics or both. Parameters: the site (track, contact, rolling stock), ``noise.*``
(:data:`rail_monitor.noise.config.NOISE_SPECS`: baseline rail roughness, CNOSSOS track type,
interpolation rule, receiver and ground, mechanics radiators) and ``state_wait_s``.

Which corrugation a pass is predicted on: the state that includes it. While corrugation/state has
a publisher, a pass waits (at most ``state_wait_s``) for the state whose stamp and last_train_id
are its own, or for any later state (the pass was not counted: a duplicate); it then takes the
latest state not newer than itself. So the result does not depend on how the two topics
interleave, and equals batch mode. A pass that waits too long takes the latest state (counted on
/diagnostics). A state with inconsistent arrays is refused with its reason on /diagnostics.
"""

from __future__ import annotations

import itertools
import sys
import time
from collections import Counter, deque
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.codec.cdr_columns import read_columns
from rail_monitor.codec.typestore import CORRUGATION_STATE
from rail_monitor.core.node_params import PREDICTOR_SPECS
from rail_monitor.core.passes import PassTable
from rail_monitor.core.timeutil import format_iso_ns
from rail_monitor.messages.fields import PassHead, heads_columns, rolling_noise_cdr, time_columns_ns
from rail_monitor.messages.output_columns import corrugation, corrugation_refusals
from rail_monitor.nodes.base import declare, isolate_failures, runs, subscribe_batched, wall_timer
from rail_monitor.nodes.pass_consumer import PassConsumerNode
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import STATE_SUB_QOS, STREAM_QOS
from rail_monitor.noise.config import NOISE_SPECS, noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import Corrugation
from rail_monitor.noise.state_of_pass import first_state_needed, state_arrived, state_index
from rail_msgs.msg import CorrugationState, RollingNoise

STATES_KEPT = 10_000  # states kept for passes still to come (the train_pass queue is as deep)


@dataclass
class _Pending:
    table: PassTable  # the passes taken with it (class defaults filled)
    row: int          # its row
    head: PassHead
    deadline: float   # monotonic [s]; -inf: do not wait


class RollingNoisePredictor(PassConsumerNode):
    EXECUTABLE = "rolling_noise_predictor"
    PARAMETERS = (*PassConsumerNode.PARAMETERS, ("noise.", NOISE_SPECS), ("", PREDICTOR_SPECS))

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("rolling_noise_predictor", **kwargs)
        cfg = noise_config(declare(self, NOISE_SPECS, prefix="noise."), prefix="")
        self.wait_s = declare(self, PREDICTOR_SPECS)["state_wait_s"]
        self.model = RollingNoiseModel(self.site, cfg)
        self.states: deque[tuple[int, str, Corrugation]] = deque(maxlen=STATES_KEPT)  # in arrival order
        self._state_stamps: deque[int] = deque(maxlen=STATES_KEPT)  # their stamps, to bisect
        self.pending: deque[_Pending] = deque()
        self.counts: Counter[str] = Counter()
        self.states_rejected: Counter[str] = Counter()
        self.pub = self.create_publisher(RollingNoise, "noise/rolling", STREAM_QOS)
        # Raw: a state is read straight from its CDR (numpy views of its amplitudes), not converted by rclpy.
        subscribe_batched(self, CorrugationState, "corrugation/state", self._on_states, STATE_SUB_QOS, self.max_batch,
                          raw=True)
        # Only while passes wait for their state: an idle predictor has no timer to wake it.
        self._waiting = wall_timer(self, 0.05, self._flush)
        self._waiting.cancel()
        self.listen()

    def key_parameters(self) -> dict[str, Any]:
        return {"models": "+".join(self.model.models), "state_wait_s": f"{self.wait_s:g}"}

    def _on_states(self, raws: list[bytes]) -> None:
        read = read_columns(CORRUGATION_STATE, raws)
        reasons = corrugation_refusals(read.values)
        for why in [str(exc) for _, exc in read.refused] + [r for r in reasons.tolist() if r]:
            self.states_rejected[why] += 1
            self.get_logger().warning(f"corrugation state refused: {why}", throttle_duration_sec=self.log_throttle_s)
        stamps, trains = time_columns_ns(read.values.header.stamp).tolist(), read.values.last_train_id
        for i in np.flatnonzero(reasons == "").tolist():
            self.states.append((stamps[i], trains[i], corrugation(read.values, i)))
            self._state_stamps.append(stamps[i])
        self._flush()

    def on_passes(self, table: PassTable, heads: list[PassHead]) -> None:
        # Always wait (a separate estimator may not be discovered yet when the first pass comes);
        # run without an estimator with state_wait_s:=0.
        wait = self.wait_s > 0
        deadline = time.monotonic() + self.wait_s if wait else float("-inf")
        self.pending.extend(_Pending(table, i, head, deadline) for i, head in enumerate(heads))
        self._flush()

    def _flush(self) -> None:
        """Predict the pending passes, in order, that have their state (or waited long enough); the
        deadline timer runs while any is left."""
        self._predict_ready()
        if self.pending and self._waiting.is_canceled():
            self._waiting.reset()
        elif not self.pending and not self._waiting.is_canceled():
            self._waiting.cancel()

    def _predict_ready(self) -> None:
        if not self.pending:
            return
        now = time.monotonic()
        pending = list(self.pending)
        states = self._states_from(min(p.head.stamp_ns for p in pending))
        stamps = np.fromiter((st for st, _, _ in states), np.int64, len(states))
        trains = [last for _, last, _ in states]
        arrived = state_arrived(stamps, trains, np.array([p.head.stamp_ns for p in pending], np.int64),
                                [p.head.train_id for p in pending])
        n = 0
        for p, has_state in zip(pending, arrived.tolist(), strict=True):
            if not has_state:
                if now < p.deadline:
                    break
                if p.deadline > float("-inf"):
                    self.counts["predicted on the latest state (waited too long)"] += 1
            n += 1
        if not n:
            return
        ready = [self.pending.popleft() for _ in range(n)]
        index = state_index(stamps, trains, np.array([p.head.stamp_ns for p in ready], np.int64),
                            [p.head.train_id for p in ready])
        self._predict(ready, [states[k][2] if k >= 0 else None for k in index.tolist()])

    def _states_from(self, stamp_ns: int) -> list[tuple[int, str, Corrugation]]:
        """The states a pass at or after stamp_ns can be predicted on (those from that stamp on, and
        the latest before it), in order: the cost of a pass does not grow with the states kept."""
        first = first_state_needed(self._state_stamps, stamp_ns)
        return list(itertools.islice(reversed(self.states), len(self.states) - first))[::-1]

    def _predict(self, ready: list[_Pending], states: list[Corrugation | None]) -> None:
        """Both models over the ready passes in one call per run of passes whose states share their
        bands (each pass on its own state's amplitudes); published pass by pass, models in order."""
        for run in runs(states, _same_bands):
            self._predict_run(ready[run], states[run])

    def _predict_run(self, ready: list[_Pending], states: list[Corrugation | None]) -> None:
        first = states[0]

        def predict(rows: slice) -> None:
            corrugation = None if first is None else Corrugation(
                first.wavelength_m, np.stack([np.asarray(s.amplitude_m) for s in states[rows]]), first.post_grinding_m)
            passes = ready[rows]
            values = self.model.predict_models(_rows(passes), (), corrugation).values()
            for data in rolling_noise_cdr(values, heads_columns([p.head for p in passes]), self.model.receiver):
                self.sent.send(self.pub, data)

        isolate_failures(len(ready), predict, lambda i, exc: self.model_error(f"pass {ready[i].head.train_id!r}", exc))

    def diagnostic_values(self) -> dict[str, Any]:
        last = self.states[-1][0] if self.states else 0
        values = {**super().diagnostic_values(), "published": sum(self.sent.values()),
                  "models": ",".join(self.model.models),
                  "pending": len(self.pending), **self.counts,
                  "corrugation_state": format_iso_ns(last) if last else "none"}
        values.update({f"state refused: {why}": n for why, n in sorted(self.states_rejected.items())})
        return values


def _same_bands(a: Corrugation | None, b: Corrugation | None) -> bool:
    """Whether two states can be predicted on together (same bands and post-grinding amplitudes)."""
    if a is None or b is None:
        return a is b
    return a is b or (np.array_equal(a.wavelength_m, b.wavelength_m)
                      and np.array_equal(a.post_grinding_m, b.post_grinding_m))


def _rows(pending: list[_Pending]) -> PassTable:
    """The pending passes as one table, in order."""
    parts = [pending[run.start].table.take(np.array([p.row for p in pending[run]]))
             for run in runs(pending, lambda a, b: a.table is b.table)]
    return parts[0] if len(parts) == 1 else PassTable.concat(parts)


def main(args: list[str] | None = None) -> int:
    return run_node(RollingNoisePredictor, args)


if __name__ == "__main__":
    sys.exit(main())
