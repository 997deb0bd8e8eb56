"""The indirect rail roughness as an observation of the corrugation state (no rclpy).

With ``residual.indirect_days`` = w > 0, time is cut into windows of w days, (k w, (k + 1) w]
from the Unix epoch (UTC), the same in every process. Each measured pass of a counted pass is
compared with the CNOSSOS-EU prediction of that pass on the state that includes it (the noise
predictor's), and its residuals and the rail's share of the combined roughness are added to the
window's fit (:class:`rail_monitor.measured.indirect.IndirectPairs`), leaving out passes measured
squealing and passes whose 500-2000 Hz residual is more than ``residual.outlier_db`` above the
running median of the last ``residual.baseline_passes`` (a wheel flat is not rail roughness). At
the first pass stamped after a window's end, the window's indirect roughness is fitted, turned
into the corrugation amplitude it implies (:func:`~rail_monitor.measured.indirect.state_observation`)
and taken by the estimator as a survey with that per-band uncertainty: a re-fit of K_b and a
Kalman update of the levels (:mod:`rail_monitor.corrugation.surveys`). Taken on a rail that has
had no survey since its last grinding: where surveys come, they calibrate and the windows are
published beside them (up to 0.30.0 the levels were carried without their covariance with K_b,
so a survey after a weak observation's partial level update over-fitted K_b; docs/models.md).

A measurement is paired once its pass is counted, in stamp order, and must arrive before the
first pass after its window's end (a replay sends each after its pass and before the next); one
that comes later joins the window then open. What is not fitted is counted by reason
(``counts``: a bad or repeated measurement, no counted pass, squealing or a wheel-defect outlier).
"""

from __future__ import annotations

import bisect
import math
from collections import Counter, OrderedDict
from dataclasses import dataclass

import numpy as np

from rail_monitor.core.passes import PassTable
from rail_monitor.core.timeutil import NS_PER_DAY, window_end_ns
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Trajectory
from rail_monitor.corrugation.surveys import KIND_GRINDING, KIND_INDIRECT, KIND_SURVEY, MaintenanceEvent, split_before
from rail_monitor.measured.config import ResidualConfig
from rail_monitor.measured.indirect import IndirectPairs, IndirectRoughness, state_observation
from rail_monitor.measured.records import Measurement, measurement_refusal
from rail_monitor.measured.residuals import Baseline, Predicted, compare
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import Corrugation

MAX_AWAITING = 10_000  # counted passes kept in a checkpoint for their measurements still to come
TEXT = ("train_id", "vehicle_class")  # PassTable's text columns
MODEL = "cnossos"  # the prediction the residuals are taken against: its transfer functions are the standard's


@dataclass(frozen=True)
class Observation:
    """One window's indirect roughness and the survey-like event it gives the state (None: not
    taken, as no band's growth is half its observed energy, or a survey came since the last
    grinding)."""

    stamp_ns: int
    window_days: float
    measured_passes: int
    indirect: IndirectRoughness
    observed_amplitude_m: np.ndarray
    event: MaintenanceEvent | None


class IndirectObserver:
    """Pairs measured pass-bys with the counted passes' states and fits one window at a time."""

    def __init__(self, model: RollingNoiseModel, cfg: ResidualConfig, bands: np.ndarray) -> None:
        self.model, self.cfg = model, cfg
        self.bands = np.asarray(bands, float)
        self.interval_ns = round(cfg.indirect_days * NS_PER_DAY)
        self.window_end_ns = 0                    # end of the open window (0: none yet)
        self.pairs = IndirectPairs.empty(len(self.bands))
        self.fitted = 0                           # measured passes in the open window's fit
        self.baseline = Baseline(cfg.baseline_passes, cfg.baseline_min_passes, cfg.outlier_db)
        # (stamp, train_id) -> (its counted table, row, state that includes it, post-grinding amplitudes)
        self.counted: OrderedDict[tuple[int, str], tuple[PassTable, int, np.ndarray, np.ndarray]] = OrderedDict()
        self.newest_counted_ns = -1
        self.queue: list[tuple[int, str]] = []    # measurements waiting for their pass, in stamp order
        self.waiting: dict[tuple[int, str], Measurement] = {}
        self.taken: OrderedDict[tuple[int, str], None] = OrderedDict()  # measured passes paired (the newest)
        self.newest_taken_ns = -1                 # stamp of the newest of them
        self.surveyed = False                     # a survey applied since the last grinding: surveys calibrate
        self.counts: Counter[str] = Counter()

    @property
    def enabled(self) -> bool:
        return self.interval_ns > 0

    def boundary(self, stamp_ns: int) -> int:
        """The end of the window holding stamp_ns [ns]."""
        return window_end_ns(stamp_ns, self.interval_ns)

    def add_measurements(self, measurements: list[Measurement]) -> None:
        for m in measurements:
            why = measurement_refusal(m, self.model.band_hz, (self.model.receiver.distance_m,
                                                              self.model.receiver.height_m),
                                      self.cfg.receiver_tolerance_m)
            if not why and (m.key in self.waiting or m.key in self.taken):
                why = "pass measured twice"
            if not why and len(self.queue) >= self.cfg.held_predictions:
                why = "too many measurements waiting for their passes"
            if why:
                self.counts[f"not fitted: {why}"] += 1
                continue
            bisect.insort(self.queue, m.key)
            self.waiting[m.key] = m
        self._drain()

    def add_counted(self, table: PassTable, traj: Trajectory) -> None:
        """The passes an advance over table (valid, class defaults filled, in stream order) counted,
        each with the state that includes it."""
        if not len(traj):
            return
        passes, amplitude, post_grinding_m = table.take(traj.index), traj.amplitude, traj.constants.grinding_amplitude
        if not self.window_end_ns:
            self.window_end_ns = self.boundary(int(passes.stamp_ns[0]))
        for i, key in enumerate(zip(passes.stamp_ns.tolist(), passes.train_id.tolist(), strict=True)):
            self.counted[key] = (passes, i, amplitude[i], post_grinding_m)
        while len(self.counted) > self.cfg.held_predictions:
            self.counted.popitem(last=False)
        self.newest_counted_ns = max(self.newest_counted_ns, int(passes.stamp_ns.max()))
        self._drain()

    def _drain(self) -> None:
        ready: list[Measurement] = []
        while self.queue:
            key = self.queue[0]
            if key not in self.counted and key[0] >= self.newest_counted_ns:
                break  # its pass may still be counted
            m = self.waiting.pop(self.queue.pop(0))
            self.taken[key] = None
            self.newest_taken_ns = max(self.newest_taken_ns, key[0])
            if len(self.taken) > self.cfg.held_predictions:
                self.taken.popitem(last=False)
            if key in self.counted:
                ready.append(m)
            else:
                self.counts["not fitted: no counted pass"] += 1
        if ready:
            self._fit(ready)

    def _fit(self, ms: list[Measurement]) -> None:
        rows = [self.counted[m.key] for m in ms]
        post = rows[0][3]
        if any(not np.array_equal(r[3], post) for r in rows):  # a grinding between them: one state a run
            cut = next(i for i, r in enumerate(rows) if not np.array_equal(r[3], post))
            self._fit(ms[:cut])
            self._fit(ms[cut:])
            return
        parts, start = [], 0
        for i in range(1, len(rows) + 1):  # consecutive rows of one counted table, taken at once
            if i == len(rows) or rows[i][0] is not rows[start][0]:
                parts.append(rows[start][0].take([r[1] for r in rows[start:i]]))
                start = i
        passes = parts[0] if len(parts) == 1 else PassTable.concat(parts)
        state = Corrugation(self.bands, np.stack([r[2] for r in rows]), post)
        p = self.model.predict(passes, MODEL, state)
        share = self.model.rail_share(passes, state)
        keep = np.zeros(len(ms), bool)
        residual = np.empty((len(ms), len(self.model.band_hz)))
        for i, m in enumerate(ms):
            raw = compare(m, Predicted(m.stamp_ns, m.train_id, MODEL, p.lp_db[i], math.nan, math.nan, math.nan),
                          self.model.band_hz)
            residual[i] = raw["residual_db"]
            _, excess, _ = self.baseline.score(float(raw["residual_mid_db"]))
            keep[i] = not m.squeal_detected and not excess > self.cfg.outlier_db
        self.counts["fitted"] += int(keep.sum())
        self.counts["not fitted: squealing or a wheel-defect outlier"] += int((~keep).sum())
        self.fitted += int(keep.sum())
        self.pairs.add(residual[keep], share[keep], passes.speed_mps[keep], self.model.band_hz, self.bands)

    def note(self, event: MaintenanceEvent) -> None:
        """A survey or grinding the state has taken: after a survey (until the next grinding) the
        windows are published but not taken, the surveys being the calibration."""
        if event.kind in (KIND_SURVEY, KIND_GRINDING):
            self.surveyed = event.kind == KIND_SURVEY

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The open window's fit, the outlier baseline and the counted passes whose measurements may
        still come (stamped after the newest measurement taken), for a checkpoint; measurements
        waiting for their passes are not kept (a replay after a restart sends them again)."""
        awaiting = [(k, v) for k, v in self.counted.items() if k[0] > self.newest_taken_ns][-MAX_AWAITING:]
        rows = [table.row(i) for _, (table, i, _, _) in awaiting]
        cols = {f"indirect_pass_{c}": np.array([r[c] for r in rows], dtype=str if c in TEXT else PassTable.DTYPES[c])
                for c in PassTable.columns()}
        nb = len(self.bands)
        return {"indirect_pairs": self.pairs.as_array(), "indirect_baseline": np.array(self.baseline.window, float),
                "indirect_scalars": np.array([self.window_end_ns, self.fitted, self.newest_taken_ns, self.surveyed],
                                             np.int64),
                "indirect_reference": np.array(self.baseline.reference), **cols,
                "indirect_pass_state": np.array([v[2] for _, v in awaiting], float).reshape(-1, nb),
                "indirect_pass_post": np.array([v[3] for _, v in awaiting], float).reshape(-1, nb)}

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        """Resume from to_arrays's records (ValueError, the observer untouched, if they are not usable;
        without them, the window stays empty)."""
        if "indirect_pairs" not in arrays:
            return
        pairs = IndirectPairs.from_array(arrays["indirect_pairs"], len(self.bands))
        window = np.asarray(arrays["indirect_baseline"], float)
        scalars = np.asarray(arrays["indirect_scalars"]).astype(np.int64, casting="same_kind")
        reference = float(arrays["indirect_reference"])
        passes = PassTable(**{c: np.asarray(arrays[f"indirect_pass_{c}"]).astype(object if c in TEXT else
                                                                                 PassTable.DTYPES[c])
                              for c in PassTable.columns()})
        state, post = np.asarray(arrays["indirect_pass_state"], float), np.asarray(arrays["indirect_pass_post"], float)
        if window.ndim != 1 or not np.all(np.isfinite(window)) or scalars.shape != (4,) \
                or np.any(scalars[:2] < 0) or scalars[3] not in (0, 1) \
                or state.shape != (len(passes), len(self.bands)) or post.shape != state.shape \
                or not (np.all(np.isfinite(state)) and np.all(post > 0)):
            raise ValueError("indirect roughness records have the wrong shape, negative counts or bad states")
        self.pairs, self.window_end_ns, self.fitted = pairs, int(scalars[0]), int(scalars[1])
        self.newest_taken_ns, self.surveyed = int(scalars[2]), bool(scalars[3])
        self.counted = OrderedDict()
        for i, key in enumerate(zip(passes.stamp_ns.tolist(), passes.train_id.tolist(), strict=True)):
            self.counted[key] = (passes, i, state[i], post[i])
        self.newest_counted_ns = int(passes.stamp_ns.max(initial=-1))
        self.baseline = Baseline(self.cfg.baseline_passes, self.cfg.baseline_min_passes, self.cfg.outlier_db)
        self.baseline.resume(window.tolist(), reference)

    def observe(self, est: CorrugationEstimator) -> Observation | None:
        """Close the open window: its indirect roughness against est's state at its end, and the
        survey-like event for the estimator (None: no measured pass fitted in it); the next window
        opens empty at the next pass."""
        model_state = Corrugation(est.bands, est.amplitude, est.grinding_amplitude)
        end, self.window_end_ns = self.window_end_ns, 0
        if not self.fitted:
            return None
        rail_db = np.interp(self.bands, self.model.grid, self.model.rail_roughness_db(model_state))
        base_db = np.interp(self.bands, self.model.grid, self.model.baseline_db)
        ind = self.pairs.estimate(self.bands, rail_db, self.cfg.prediction_sd_db)
        amplitude, var = state_observation(ind, base_db, model_state.post_grinding_m)
        if self.surveyed:
            amplitude = np.full(len(self.bands), np.nan)
        ok = np.isfinite(amplitude)
        event = None
        if ok.any():
            event = MaintenanceEvent(end, KIND_INDIRECT, self.bands[ok], amplitude[ok], var[ok])
        out = Observation(end, self.interval_ns / NS_PER_DAY, self.fitted, ind, amplitude, event)
        self.pairs = IndirectPairs.empty(len(self.bands))
        self.fitted = 0
        self.counts["windows fitted"] += 1
        self.counts["observations taken"] += event is not None
        return out


def next_cut(stamps_ns: np.ndarray, pending: list[MaintenanceEvent], observer: IndirectObserver | None
             ) -> tuple[int, bool] | None:
    """Where the next survey, grinding or window's observation falls among passes about to be
    counted (stamps [ns], in stream order): (passes before it, whether it is the observation);
    None when nothing falls inside them. An event and a window's end on the same pass: the event
    first."""
    cuts = []
    if pending:
        cuts.append((split_before(stamps_ns, pending[0].stamp_ns), False))
    if observer is not None and observer.enabled and len(stamps_ns):
        if not observer.window_end_ns:
            observer.window_end_ns = observer.boundary(int(stamps_ns[0]))
        cuts.append((split_before(stamps_ns, observer.window_end_ns), True))
    cut = min(cuts, default=None)
    return cut if cut is not None and cut[0] < len(stamps_ns) else None
