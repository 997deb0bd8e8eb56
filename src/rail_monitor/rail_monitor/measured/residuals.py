"""Measured minus predicted pass-by noise, and the site's running baseline of it.

Per band, the residual is the measured Lp,eq over the pass-by time minus the model's (both at the
ISO 3095:2013 position, 7.5 m / 1.2 m); overall, the same for LpAeq,Tp, LpAFmax and TEL. The
500-2000 Hz residual is the difference of the energy sums of those bands: there a wheel flat or
out-of-round wheel raises rolling noise (Thompson, Railway Noise and Vibration, Elsevier 2009,
ch. 7: impact noise from wheel flats), and there corrugation of 15-60 mm at 80-120 km/h radiates.

A model is biased at any one site (its receptances and roughness are not the site's), so a pass
is scored against the site's baseline: the running median of the 500-2000 Hz residual of the last
``residual.baseline_passes`` passes, leaving out passes more than ``residual.outlier_db`` above
it (so defective wheels do not drag it up). The excess over the baseline is the wheel-defect
score; the baseline's rise since it was first full is the drift (the rail roughening faster than
the model says).

Uncertainty: a predicted band level has ``residual.prediction_sd_db``; a measured band level the
instrument's, taken as the IEC 61672-1:2013 acceptance limit at 1 kHz (class 1: 1.1 dB, class 2:
1.4 dB) over sqrt(3), the standard uncertainty of a rectangular distribution (JCGM 100:2008,
GUM, 4.3.7).

Order: measurements are scored in stamp order (train_id breaking ties), each once its pass's
prediction of every model (the squeal model's risk too) is in, so the baseline is the same
however a measurement and its own pass's predictions interleave, live or in batch, as long as
it arrives before any later pass's predictions (a replay sends it after its pass and before the
next). One that arrives after a later measurement was scored is scored on arrival and counted in
``late``. A measurement waits while a pass at or after its stamp may still be predicted; once
every model has predicted a later pass and none predicted its own, it is refused (no such pass,
or the pass was rejected).
"""

from __future__ import annotations

import bisect
import math
from collections import Counter, OrderedDict, deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from itertools import repeat
from typing import Any, NamedTuple

import numpy as np

from rail_monitor.measured.config import ResidualConfig
from rail_monitor.measured.records import Measurement, band_index, measurement_refusal
from rail_monitor.models.levels import energy_sum

INSTRUMENT_SD_DB = {1: 1.1 / math.sqrt(3.0), 2: 1.4 / math.sqrt(3.0)}
MID_BAND_HZ = (500.0, 2000.0)
UNPAIRED = "no prediction for this pass (no such pass, or it was rejected)"


class Predicted(NamedTuple):
    """One model's prediction of one pass (units as in rail_msgs/RollingNoise). A named tuple: the
    engine holds one per pass and model for the measurements to come, and a tuple is the cheapest
    record to build."""

    stamp_ns: int
    train_id: str
    model: str
    lp_db: np.ndarray           # (B,) on the model's bands [dB re 20 uPa]
    lpaeq_tp_dba: float
    lpafmax_dba: float
    tel_dba: float
    squeal_risk: int = 0        # model "squeal": the pass's SquealPrediction risk (RISK_*); noise models: unused


@dataclass(frozen=True)
class Residual:
    """Measured minus predicted noise of one pass for one model (fields and units as in
    rail_msgs/NoiseResidual)."""

    stamp_ns: int
    train_id: str
    model: str
    band_centre_hz: np.ndarray
    residual_db: np.ndarray
    residual_lpaeq_dba: float
    residual_lpafmax_dba: float
    residual_tel_dba: float
    residual_mid_db: float
    baseline_mid_db: float
    drift_db: float
    prediction_sd_db: float
    measurement_sd_db: float
    excess_mid_db: float
    loudest_vehicle_id: str
    loudest_vehicle_excess_db: float
    squeal_detected: bool
    vehicle_id: tuple[str, ...] = ()
    squeal_risk: int = 0        # the squeal model's risk of the pass (SquealPrediction.RISK_*)


class Baseline:
    """The running median of the 500-2000 Hz residual and its value when first full."""

    def __init__(self, passes: int, min_passes: int, outlier_db: float) -> None:
        self.window: deque[float] = deque(maxlen=passes)   # in arrival order
        self._sorted: list[float] = []                     # the same values, sorted (the median in O(log n))
        self.min_passes, self.outlier_db = min_passes, outlier_db
        self.reference = math.nan

    def resume(self, window: list[float], reference: float) -> None:
        """Continue from a window of values (oldest first; the newest maxlen kept) and its reference."""
        for v in window[-self.window.maxlen:]:
            self.window.append(v)
            bisect.insort(self._sorted, v)
        self.reference = reference

    def median(self) -> float:
        """The window's median, as numpy's (the mean of the middle two of an even count) [dB]."""
        s, n = self._sorted, len(self._sorted)
        return s[n // 2] if n % 2 else (s[n // 2 - 1] + s[n // 2]) / 2.0

    def score(self, mid_db: float) -> tuple[float, float, float]:
        """(baseline before this pass, excess of the pass over it, drift of the baseline) [dB];
        then the pass joins the window unless it is an outlier or not finite."""
        base = self.median() if len(self.window) >= self.min_passes else math.nan
        if math.isnan(self.reference) and len(self.window) == self.window.maxlen:
            self.reference = base
        excess = mid_db - base
        if math.isfinite(mid_db) and not excess > self.outlier_db:
            if len(self.window) == self.window.maxlen:
                del self._sorted[bisect.bisect_left(self._sorted, self.window[0])]
            self.window.append(mid_db)
            bisect.insort(self._sorted, mid_db)
        return base, excess, base - self.reference


def compare(m: Measurement, p: Predicted, band_hz: np.ndarray) -> dict[str, float | np.ndarray]:
    """The residuals of a measurement against a prediction on the model's bands (band_hz [Hz]),
    without the baseline."""
    index = band_index(band_hz, m.band_centre_hz)
    residual = np.full(len(band_hz), np.nan)
    residual[index] = np.asarray(m.leq_db, float) - p.lp_db[index]
    centre = band_hz[index]
    mid = (centre >= MID_BAND_HZ[0] * 0.98) & (centre <= MID_BAND_HZ[1] * 1.02)
    mid_db = float(energy_sum(np.asarray(m.leq_db)[mid]) - energy_sum(p.lp_db[index[mid]])) if mid.any() else math.nan
    loudest, excess = "", math.nan
    seg = np.asarray(m.vehicle_lpaeq_dba, float)
    if len(seg) >= 2:
        k = int(np.argmax(seg))
        loudest, excess = m.vehicle_id[k], float(seg[k] - energy_sum(seg) + 10.0 * math.log10(len(seg)))
    return {"residual_db": residual, "residual_lpaeq_dba": m.lpaeq_tp_dba - p.lpaeq_tp_dba,
            "residual_lpafmax_dba": m.lpafmax_dba - p.lpafmax_dba, "residual_tel_dba": m.tel_dba - p.tel_dba,
            "residual_mid_db": mid_db, "loudest_vehicle_id": loudest, "loudest_vehicle_excess_db": excess}


SQUEAL = "squeal"  # the squeal model's "prediction" of a pass: its risk only


class ResidualTracker:
    """Pairs measurements with their pass's predictions (every noise model's, and the squeal
    model's risk), scores them in stamp order against a baseline per noise model, and counts what
    it refuses by reason."""

    def __init__(self, cfg: ResidualConfig, band_hz: np.ndarray, receiver_m: tuple[float, float],
                 models: Sequence[str]) -> None:
        self.cfg, self.receiver_m, self.noise_models = cfg, receiver_m, tuple(models)
        self.models = (*self.noise_models, SQUEAL)
        self.band_hz = np.asarray(band_hz, float)
        self.predictions: OrderedDict[tuple[int, str], dict[str, Predicted]] = OrderedDict()
        self.newest = {m: -1 for m in self.models}       # newest stamp predicted per model [ns]
        self.queue: list[tuple[int, str]] = []            # measured passes waiting, in stamp order
        self.waiting: dict[tuple[int, str], Measurement] = {}
        self.scored: OrderedDict[tuple[int, str], None] = OrderedDict()
        self.baselines = {m: Baseline(cfg.baseline_passes, cfg.baseline_min_passes, cfg.outlier_db)
                          for m in self.noise_models}
        self.refused: Counter[str] = Counter()
        self.taken = 0
        self.late = 0  # measurements scored after a later one

    def add_measurement(self, m: Measurement) -> list[Residual]:
        """Take a measurement; the residuals it completes (maybe of earlier ones too), in order."""
        self.taken += 1
        why = measurement_refusal(m, self.band_hz, self.receiver_m, self.cfg.receiver_tolerance_m)
        if not why and (m.key in self.waiting or m.key in self.scored):
            why = "pass measured twice"
        if not why and len(self.queue) >= self.cfg.held_predictions:  # far-future stamps must not pile up
            why = "too many measurements waiting for their passes (residual.held_predictions)"
        if why:
            self.refused[why] += 1
            return []
        if self.scored and m.key < next(reversed(self.scored)):
            self.late += 1
        bisect.insort(self.queue, m.key)
        self.waiting[m.key] = m
        return self._drain()

    def add_predictions(self, predictions: Sequence[Predicted]) -> list[Residual]:
        """Take predictions (each model's in stamp order); the residuals they complete, in order."""
        for p in predictions:
            self.predictions.setdefault((p.stamp_ns, p.train_id), {})[p.model] = p
            self.newest[p.model] = max(self.newest[p.model], p.stamp_ns)
        while len(self.predictions) > self.cfg.held_predictions:
            self.predictions.popitem(last=False)
        return self._drain()

    def finish(self) -> None:
        """Refuse the measurements still waiting (no prediction will come: the history ended)."""
        if self.queue:
            self.refused[UNPAIRED] += len(self.queue)
        self.queue, self.waiting = [], {}

    def _drain(self) -> list[Residual]:
        out: list[Residual] = []
        while self.queue:
            key = self.queue[0]
            have = self.predictions.get(key, {})
            if all(m in have for m in self.models):
                out += self._score(self.waiting.pop(key), have)
            elif all(self.newest[m] > key[0] for m in self.models):
                self.refused[UNPAIRED] += 1
                del self.waiting[key]
            else:
                break
            self.queue.pop(0)
        return out

    def _score(self, m: Measurement, predicted: dict[str, Predicted]) -> list[Residual]:
        self.scored[m.key] = None
        while len(self.scored) > self.cfg.held_predictions:
            self.scored.popitem(last=False)
        out = []
        risk = predicted[SQUEAL].squeal_risk
        for model in self.noise_models:
            raw = compare(m, predicted[model], self.band_hz)
            base, excess, drift = self.baselines[model].score(float(raw["residual_mid_db"]))
            out.append(Residual(m.stamp_ns, m.train_id, model, self.band_hz, baseline_mid_db=base, drift_db=drift,
                                prediction_sd_db=self.cfg.prediction_sd_db,
                                measurement_sd_db=INSTRUMENT_SD_DB[m.instrument_class], excess_mid_db=excess,
                                squeal_detected=m.squeal_detected, vehicle_id=tuple(m.vehicle_id),
                                squeal_risk=risk, **raw))
        return out


def predictions_of(passes: Any, noise: Mapping[str, Any], squeal_risk: np.ndarray, rows: slice = slice(None)
                   ) -> list[Predicted]:
    """The predictions of the passes at rows (a slice of passes, a PassTable, of each model's
    NoisePrediction and of squeal_risk): each noise model's in pass order, then the squeal
    model's risk (ResidualTracker.add_predictions keeps each model's in stamp order)."""
    stamps, trains = passes.stamp_ns[rows].tolist(), passes.train_id[rows].tolist()
    out: list[Predicted] = []
    for m, p in noise.items():
        out += map(Predicted, stamps, trains, repeat(m), p.lp_db[rows], p.lpaeq_tp_dba[rows].tolist(),
                   p.lpafmax_dba[rows].tolist(), p.tel_dba[rows].tolist())
    none = np.zeros(0)
    out += map(Predicted, stamps, trains, repeat(SQUEAL), repeat(none), repeat(math.nan), repeat(math.nan),
               repeat(math.nan), np.asarray(squeal_risk[rows], int).tolist())
    return out
