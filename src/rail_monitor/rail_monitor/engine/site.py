"""A site's engine: every state of a site advanced by its inputs in stamp order, the same code
for batch mode and the live graph (no rclpy).

It holds the corrugation state with its pending surveys and grinding and its indirect roughness
windows (:mod:`rail_monitor.engine.corrugation_site`), the alert windows and standing alerts, the
residual tracker and its baselines, and the states a later pass may be predicted on. Inputs:
passes (:meth:`SiteEngine.feed`, a chunk at a time: a history's chunk in batch, a callback's
backlog live), surveys and grinding (``corrugation.take``) and measured pass-bys
(:meth:`SiteEngine.take_measurements`). Outputs: what the live graph publishes, pass for pass
(:class:`rail_monitor.engine.result.SiteOutputs`): the squeal prediction of every accepted pass,
the corrugation state after every counted pass, the rolling noise of every accepted pass on the
state that includes it, the alert events, residuals and indirect roughness, the grinding outlook
made on each survey, grinding or indirect observation applied (economics.outlook, the input of a
network's programme), and the speed advice on the final state (:meth:`SiteEngine.finish`). Any
chunking gives one call's outputs.
"""

from __future__ import annotations

import bisect
import os
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rail_monitor.advice.consequences import Consequences
from rail_monitor.advice.plan import SpeedAdvice, advise_or_none
from rail_monitor.alerts.config import RISK_NAMES
from rail_monitor.alerts.manager import Alert, AlertManager
from rail_monitor.core.errors import PassOrderError
from rail_monitor.core.passes import PassTable, publishable, reject_ahead, rejection_reasons, with_class_defaults
from rail_monitor.core.timeutil import fits_time_msg, format_iso_ns
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Trajectory
from rail_monitor.corrugation.surveys import MaintenanceEvent, in_time_order
from rail_monitor.economics.options import configured_outlook
from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.engine import checkpoint
from rail_monitor.engine.corrugation_site import CorrugationSite
from rail_monitor.engine.noise_chunks import noise_on_states, pool_of
from rail_monitor.engine.result import SiteOutputs
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.engine.squeal_site import SquealSite
from rail_monitor.measured.observer import IndirectObserver, Observation
from rail_monitor.measured.records import Measurement
from rail_monitor.measured.residuals import Residual, ResidualTracker, predictions_of
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import NoisePrediction, NoiseRows
from rail_monitor.noise.state_of_pass import state_index
from rail_monitor.squeal.predict import predict as predict_squeal

HISTORY_CHUNK = 16_384  # passes per advance_history call: bounds its (passes x bands x components) arrays,
#                         and the noise of one chunk is predicted while the next is advanced
OUT_OF_ORDER = "older than a pass already taken (the engine takes passes in stamp order)"
PAIR_BLOCK = 1_000  # passes whose predictions are given to the residual tracker at once (at most half it holds)


@dataclass
class _Tail:
    """The newest corrugation states of the chunks so far: the latest state and every state of its
    stamp, all a later pass can be predicted on (passes come in time order)."""

    stamp_ns: np.ndarray
    train_id: list[str]
    amplitude: np.ndarray  # (K, B) [m]

    def then(self, traj: Trajectory) -> _Tail:
        stamps = np.concatenate([self.stamp_ns, traj.stamp_ns])
        trains = self.train_id + traj.train_id.tolist()
        return _Tail(stamps, trains, np.concatenate([self.amplitude, traj.amplitude]))

    def last_stamp(self) -> _Tail:
        keep = np.flatnonzero(self.stamp_ns == self.stamp_ns[-1]) if len(self.stamp_ns) else np.arange(0)
        return _Tail(self.stamp_ns[keep], [self.train_id[k] for k in keep.tolist()], self.amplitude[keep])


class SiteEngine:
    """Every state of a site, fed its inputs in stamp order; it carries from one chunk of passes
    to the next what one call would (the corrugation state, the alert windows and standing alerts,
    the stream's newest pass, the states a later pass may be predicted on), so any chunking gives
    one call's outputs.

    values: the site's flat parameters; estimator: a state to continue from (e.g. a checkpoint),
    default the post-grinding state; threads: for the independent parts (squeal beside the
    corrugation history; the noise chunks of every model), 0: one per core. numpy releases the
    interpreter lock in its array loops, so the threads use the cores; the chunks are the same
    whatever the count, so the results are too. engine: "numba" (compiled kernels, for many
    passes at once) or "numpy" (their twins, the same arithmetic: the live graph, which keeps
    numba's import out of its start-up).

    Chunks follow each other in time: a chunk with a pass older than an earlier chunk's newest is
    refused whole (PassOrderError) by :meth:`feed`, while :meth:`feed` with ``late=True`` (a live
    stream) rejects those passes alone, with their reason (stamps that builtin_interfaces/Time
    cannot hold aside, which are left out).

    events: the history's surveys and grinding events (MaintenanceEvent), each applied before the
    first pass stamped later than it (those after the last pass at finish()); more arrive through
    ``corrugation.take``. One refused is counted in ``events_refused`` by reason and changes nothing.
    measurements: measured pass-bys (rail_monitor.measured), more through
    :meth:`take_measurements`, each taken once the passes up to its stamp are, paired and scored
    (``tracker.refused`` counts the refused), their residuals feeding the alerts; with
    ``residual.indirect_days`` each window's indirect roughness is taken as a survey
    (``observer``, ``observations``)."""

    def __init__(self, values: Mapping[str, Any], estimator: CorrugationEstimator | None = None,
                 threads: int = 0, events: Sequence[MaintenanceEvent] = (),
                 measurements: Sequence[Measurement] = (), engine: str = "numba") -> None:
        self.cfg = SiteConfig.from_values(values)
        self.site, self.margins = self.cfg.site, self.cfg.stamps
        self.estimator = estimator or CorrugationEstimator(self.site, self.cfg.corrugation)
        self.estimator.engine = engine
        self.model = RollingNoiseModel(self.site, self.cfg.noise, engine=engine)
        # The alerts' lead time is the state's (a resumed estimator's own configuration).
        self.alerts = AlertManager(replace(self.cfg.alerts, lead_time_days=self.estimator.cfg.lead_time_days))
        self.threads = threads or os.cpu_count() or 1
        self.newest_sent_ns = 0                          # the pass source's ahead-of-stream reference
        self.newest_taken_ns = self.estimator.newest_ns  # the nodes' reference
        self.newest_ns = np.iinfo(np.int64).min          # newest stamp given so far (a chunk's order check)
        self._newest_accepted_ns = self.newest_ns        # the floor: older passes are out of order (a
                                                         # rejected pass, one far ahead, sets none)
        self._clock_ns: int | None = None                # the live clock of the chunk being fed
        self.measured_live = False                       # measurements may come after their passes (live)
        self.left_out: Counter[str] = Counter()
        self._tail = _Tail(np.zeros(0, np.int64), [], np.zeros((0, len(self.estimator.bands))))
        self._held: list[Alert] = []                     # events a later chunk may still precede
        self.trailing_events: list[MaintenanceEvent] = []
        self.trailing_measurements: list[Measurement] = []
        self._measurements = sorted(measurements, key=lambda m: m.key)  # not yet taken, by pass
        receiver = self.model.receiver
        rcfg = self.cfg.residual
        self.tracker = ResidualTracker(rcfg, self.model.band_hz, (receiver.distance_m, receiver.height_m),
                                       self.model.models)
        observer = IndirectObserver(self.model, rcfg, self.estimator.bands) if rcfg.indirect_days > 0 else None
        self.squeal = SquealSite(self.site, self.cfg.squeal, RISK_NAMES.index(self.cfg.alerts.squeal_min_risk),
                                 rcfg.held_predictions)
        self.squeal.expect(self._measurements)
        # Events are checked against the passes taken when they fall due, as the node checks them on arrival.
        self.corrugation = CorrugationSite(self.estimator, observer, self._event_ahead)
        self.corrugation.pending = in_time_order(events)
        self.corrugation.on_event = self._on_event
        self.corrugation.on_observation = self._on_observation
        self.corrugation.outlook = self._outlook
        self._consequences: Consequences | None = None
        self._parts: list[SiteOutputs] = []  # the segments of the chunk being fed

    def resume(self, path: str) -> tuple[Any, list[str]]:
        """Continue from the newest readable checkpoint at path (engine.checkpoint.resume): the file
        loaded (None: none there, a fresh history) and one line per unreadable file passed over."""
        used, skipped = checkpoint.resume(self.estimator, path, self.observer, self.squeal)
        self.newest_taken_ns = self.estimator.newest_ns
        self.alerts = AlertManager(replace(self.cfg.alerts, lead_time_days=self.estimator.cfg.lead_time_days))
        return used, skipped

    @property
    def observer(self) -> IndirectObserver | None:
        return self.corrugation.observer

    @property
    def events_refused(self) -> Counter[str]:
        """Surveys, grinding and indirect observations refused, by reason (each changed nothing)."""
        return self.corrugation.refused

    def feed(self, passes: PassTable, late: bool = False, clock_ns: int | None = None) -> SiteOutputs:
        """The outputs of the next chunk of passes, with the events due within it applied. A pass
        older than an earlier chunk's newest refuses the chunk (PassOrderError, the run left as it
        was); with ``late``, a pass older than the newest accepted is rejected alone (OUT_OF_ORDER).
        clock_ns: a live clock [ns] the passes may not lie too far ahead of
        (stamps.max_ahead_of_clock_s)."""
        stamps = passes.stamp_ns[fits_time_msg(passes.stamp_ns)]
        if not late and len(stamps) and int(stamps.min()) < self.newest_ns:
            raise PassOrderError(f"passes out of time order: a chunk has a pass at {format_iso_ns(int(stamps.min()))}, "
                             f"before {format_iso_ns(self.newest_ns)} of an earlier one")
        # In order (not late), no pass is older than the floor: the chunk check above is stricter.
        floor_ns = self._newest_accepted_ns
        self._clock_ns = clock_ns
        self.newest_ns = max(self.newest_ns, int(stamps.max(initial=self.newest_ns)))
        self._parts = []
        for part in self.corrugation.segments(passes):
            self._parts.append(self._segment(part, floor_ns))
        parts, self._parts = self._parts, []
        return parts[0] if len(parts) == 1 else SiteOutputs.merged(parts, [], None)

    def take_measurements(self, measurements: Sequence[Measurement]) -> None:
        """Measured pass-bys arriving (live, ``measured_live``: every prediction is held for them,
        residual.held_predictions at most): taken with the passes up to their stamps (or settle())."""
        for m in measurements:
            bisect.insort(self._measurements, m, key=lambda x: x.key)
        self.squeal.take(measurements)

    def settle(self) -> tuple[list[Measurement], list[Residual], list[Alert]]:
        """What the inputs so far give without a later pass (live, when the stream is idle): the
        waiting measurements of passes already accepted, paired and scored, and every alert event,
        those held back for a later chunk included (the same events in (stamp, kind, key) order)."""
        taken, residuals = self._take_measurements(self._newest_accepted_ns)
        self.alerts.on_residuals(residuals)
        events, self._held = sorted(self._held + self.alerts.take_events(), key=_alert_key), []
        return taken, residuals, events

    def _event_ahead(self, stamp_ns: int) -> str:
        why = np.array([""], dtype=object)
        reject_ahead(np.array([stamp_ns]), why, self.newest_taken_ns, self.margins)
        return str(why[0])

    def _on_event(self, event: MaintenanceEvent, fit: object, why: str) -> None:
        """A survey or grinding of the history (applied or refused) goes with the segment before it;
        a window's own observation goes with it as an observation."""
        part = self._parts[-1] if self._parts else None
        if part is None:  # taken on arrival between chunks (live): its outlook waits in corrugation.outlooks
            return
        if not (part.observations and part.observations[-1].event is event):
            part.events.append(event)
        part.outlooks.extend(self.corrugation.take_outlooks())

    def consequences(self) -> Consequences:
        """What a pass's speed does besides corrugation: the engine's noise model and squeal parameters."""
        if self._consequences is None:
            self._consequences = Consequences(self.site, self.model, self.cfg.squeal)
        return self._consequences

    def _outlook(self) -> SiteOutlook:
        """The site's grinding outlook now, with the options its economics.options offer."""
        return configured_outlook(self.estimator, self.cfg.economics, self.consequences)

    def _on_observation(self, obs: Observation) -> None:
        self._parts[-1].observations.append(obs)

    def _segment(self, passes: PassTable, floor_ns: int) -> SiteOutputs:
        table, left_out = publishable(passes, self.margins, self.newest_sent_ns)
        self.left_out.update(left_out)
        self.newest_sent_ns = max(self.newest_sent_ns, int(table.stamp_ns.max(initial=0)))
        reasons = rejection_reasons(table, self.site)
        reasons[(reasons == "") & (table.stamp_ns < floor_ns)] = OUT_OF_ORDER
        self.newest_taken_ns = reject_ahead(table.stamp_ns, reasons, self.newest_taken_ns, self.margins,
                                           self._clock_ns)
        accepted = with_class_defaults(table.take(reasons == ""), self.site)
        self._newest_accepted_ns = int(accepted.stamp_ns.max(initial=self._newest_accepted_ns))
        with pool_of(self.threads) as pool:
            squeal_job = pool.submit(self._squeal, accepted)
            # The corrugation history in chunks on this thread, each chunk's noise on the pool while
            # the next is advanced (the estimator carries the kept passes, _Tail the states a later
            # pass may be predicted on: the chunks give one call's states and predictions).
            trajs, noise_jobs, rows = [], [], NoiseRows(len(accepted))
            for lo in range(0, max(len(accepted), 1), HISTORY_CHUNK):
                part = accepted.take(slice(lo, lo + HISTORY_CHUNK))
                traj = self.corrugation.advance(part)
                states = self._tail.then(traj)
                on = state_index(states.stamp_ns, states.train_id, part.stamp_ns, part.train_id)
                noise_jobs += noise_on_states(pool, self.model, part, states.amplitude, traj.constants, on, rows, lo)
                self._tail = states.last_stamp()
                trajs.append((lo, traj))
            traj = trajs[0][1] if len(trajs) == 1 else Trajectory.concat(trajs)
            squeal = squeal_job.result()
            calibrations = self.squeal.take_calibrations()
            for c in calibrations:
                self.alerts.on_squeal_fit(c.stamp_ns, c.share_windows())
            _feed_alerts(self.alerts, table, reasons, accepted, squeal, traj)  # while the noise is finishing
            for job in noise_jobs:
                job.result()
            noise = rows.predictions()
        measured, residuals = self._measured(table, accepted, noise, squeal["risk"])
        self.alerts.on_residuals(residuals)
        for name, out in noise.items():
            self.alerts.on_noise(accepted.stamp_ns, name, out.per_pass())
        events = self.alerts.take_events()
        events = sorted(self._held + events, key=_alert_key)
        later = int(table.stamp_ns[-1]) if len(table) else np.iinfo(np.int64).min
        self._held = [a for a in events if a.stamp_ns >= later]  # may tie with the next chunk's first pass
        return SiteOutputs(site=self.site, passes=table, reasons=reasons, accepted=accepted, squeal=squeal,
                           trajectory=traj, noise=noise, alerts=[a for a in events if a.stamp_ns < later],
                           standing=self.standing(), advice=None, estimator=self.estimator,
                           receiver=self.model.receiver, left_out=dict(left_out), measurements=measured,
                           residuals=residuals, calibrations=calibrations)

    def _squeal(self, accepted: PassTable) -> dict[str, np.ndarray]:
        """The squeal of the passes, each on the curves fitted before it (engine.squeal_site)."""
        parts = []
        for part in self.squeal.segments(accepted):
            parts.append(predict_squeal(self.cfg.squeal, self.squeal.site, part))
            self.squeal.hold(part)
        return parts[0] if len(parts) == 1 else {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}

    def _measured(self, table: PassTable, accepted: PassTable, noise: dict[str, NoisePrediction],
                  squeal_risk: np.ndarray) -> tuple[list[Measurement], list[Residual]]:
        """The measurements of this chunk's passes (stamped up to its last), paired with the
        predictions as alert_manager pairs them."""
        if not (self.measured_live or self._measurements or self.tracker.queue):
            return [], []
        taken: list[Measurement] = []
        out: list[Residual] = []

        def take(upto: int) -> None:
            more, residuals = self._take_measurements(upto)
            taken.extend(more)
            out.extend(residuals)

        # Block by block, so that the tracker holds no more than a block of predictions unpaired
        # (it keeps residual.held_predictions, however long the chunk).
        cut = np.iinfo(np.int64).min
        block = max(1, min(PAIR_BLOCK, self.tracker.cfg.held_predictions // 2))
        for lo in range(0, len(accepted), block):
            cut = max(cut, int(accepted.stamp_ns[lo:lo + block].max()))
            take(cut)
            out.extend(self.tracker.add_predictions(predictions_of(accepted, noise, squeal_risk,
                                                                   slice(lo, lo + block))))
        take(max(cut, int(table.stamp_ns.max()) if len(table) else cut))
        return taken, out

    def _take_measurements(self, upto: int) -> tuple[list[Measurement], list[Residual]]:
        """The measurements stamped up to upto (as the replayer sends them before the next pass),
        given to the indirect windows and the tracker; the residuals they complete."""
        n = bisect.bisect_right([m.stamp_ns for m in self._measurements], upto)
        taken, self._measurements = self._measurements[:n], self._measurements[n:]
        if self.observer is not None:
            self.observer.add_measurements(taken)
        return taken, [r for m in taken for r in self.tracker.add_measurement(m)]

    def standing(self) -> list[Alert]:
        return sorted(self.alerts.standing.values(), key=_alert_key)

    def finish(self) -> tuple[list[Alert], SpeedAdvice | None]:
        """The events held back for a later chunk, and the speed advice on the final state (after
        the surveys and grinding later than every pass, kept in ``trailing_events``)."""
        self.trailing_events = self.corrugation.finish()
        self.trailing_measurements, self._measurements = self._measurements, []
        for m in self.trailing_measurements:
            self.tracker.add_measurement(m)
        self.tracker.finish()
        held, self._held = self._held, []
        with pool_of(self.threads) as pool:
            return held, advise_or_none(self.estimator, self.consequences(), pool)


def _alert_key(a: Alert) -> tuple[int, int, str, bool]:
    return a.stamp_ns, a.kind, a.key, a.active


def _feed_alerts(alerts: AlertManager, table: PassTable, reasons: np.ndarray, accepted: PassTable,
                 squeal: dict[str, np.ndarray], traj: Trajectory) -> None:
    """The alert manager over the input, squeal and state streams, a stream at once. Streams do not
    interact and their events are put in one order afterwards, so the noise and the residuals may be
    fed later."""
    alerts.on_train_passes(table.stamp_ns, reasons != "")
    alerts.on_squeal(accepted.stamp_ns, squeal["risk"])
    c, f = traj.constants, traj.forecast
    alerts.on_states(traj.stamp_ns, c.bands, traj.amplitude, c.threshold, f.days_to_threshold, f.grinding_due,
                     f.grinding_due_ns)
