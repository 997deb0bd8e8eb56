"""Model outputs a node takes from another (CorrugationState, RollingNoise, SquealPrediction),
taken together as columns (codec.cdr_columns): why each is unusable, and what the node uses of
them (a state's corrugation, runs of states as the alert manager's series, predictions for the
measured noise). The one place for each check on them: any publisher may write to a topic, so a
node refuses (and counts) what it cannot use instead of predicting or raising alerts from it.

A column of per-band values is (states, bands) where every state has as many values, else one
array per state; each check is written once over a (states, bands) block and applied to the
block, or to each state alone.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rail_monitor.alerts.config import NOISE_METRICS
from rail_monitor.core.timeutil import fits_time_msg
from rail_monitor.measured.residuals import SQUEAL, Predicted
from rail_monitor.messages.fields import time_columns_ns
from rail_monitor.noise.config import MODELS
from rail_monitor.noise.records import Corrugation
from rail_monitor.squeal.config import RISK_HIGH

LENGTHS = "wavelength_m, amplitude_m and post_grinding_m differ in length, or are empty"
WAVELENGTH = "a wavelength is not positive and finite"
AMPLITUDE = "an amplitude is negative or not finite"
THRESHOLD = "threshold_m is not one positive, finite value per band"
DAYS = "days_to_threshold is NaN or negative"
STAMP = "stamp not set, or before 1970"
MODEL = "model unknown"
LEVEL = "a single-number level is not finite"
RISK = "risk unknown"


def _blocks(values: Any, names: tuple[str, ...]) -> list[tuple[slice | int, list[np.ndarray]]]:
    """The per-band columns as one (states, bands) block each, or a (1, bands) block per state."""
    cols = [getattr(values, n) for n in names]
    if all(isinstance(c, np.ndarray) for c in cols):
        return [(slice(None), [np.asarray(c, float) for c in cols])]
    return [(i, [np.asarray(c[i], float).reshape(1, -1) for c in cols]) for i in range(len(cols[0]))]


def _first(reasons: np.ndarray, bad: np.ndarray, why: str) -> None:
    """Give the states that are bad and have no reason yet this one (checks run in order)."""
    reasons[bad & (reasons == "")] = why


def corrugation_refusals(values: Any) -> np.ndarray:
    """Why each state's bands and amplitudes are unusable ('' when usable), in the order checked:
    the lengths, the wavelengths, the amplitudes (post-grinding ones too)."""
    out = np.full(len(values.header.frame_id), "", object)
    for rows, (wl, amp, post) in _blocks(values, ("wavelength_m", "amplitude_m", "post_grinding_m")):
        why = np.full(len(wl), "", object)
        if not (wl.shape[1] == amp.shape[1] > 0 and post.shape[1] in (0, wl.shape[1])):
            why[:] = LENGTHS
        else:
            _first(why, ~np.all(np.isfinite(wl) & (wl > 0), axis=1), WAVELENGTH)
            _first(why, ~(np.all(np.isfinite(amp) & (amp >= 0), axis=1) & np.all(np.isfinite(post) & (post >= 0),
                                                                                  axis=1)), AMPLITUDE)
        out[rows] = why if isinstance(rows, slice) else why[0]
    return out


def state_refusals(values: Any) -> np.ndarray:
    """Why each state is unusable for alerts ('' when usable): its bands and amplitudes, then its
    thresholds, its forecast and its stamp."""
    out = corrugation_refusals(values)
    for rows, (wl, thr) in _blocks(values, ("wavelength_m", "threshold_m")):
        bad = np.full(len(wl), thr.shape[1] != wl.shape[1])
        if thr.shape[1] == wl.shape[1]:
            bad = ~np.all(np.isfinite(thr) & (thr > 0), axis=1)
        part = out[rows] if isinstance(rows, slice) else out[rows:rows + 1]
        _first(part, bad, THRESHOLD)
    days = np.asarray(values.days_to_threshold, float)
    _first(out, np.isnan(days) | (days < 0), DAYS)
    _first(out, _bad_stamp(values), STAMP)
    return out


def _bad_stamp(values: Any) -> np.ndarray:
    """Header stamps not set, before 1970 or past what builtin_interfaces/Time holds."""
    stamp = time_columns_ns(values.header.stamp)
    return ~((stamp > 0) & fits_time_msg(stamp))


def noise_refusals(values: Any) -> np.ndarray:
    """Why each RollingNoise is unusable ('' when usable): its model, its single-number levels, its stamp."""
    out = np.full(len(values.model), "", object)
    _first(out, np.array([m not in MODELS for m in values.model], bool), MODEL)
    _first(out, ~np.all([np.isfinite(getattr(values, k)) for k in NOISE_METRICS], axis=0), LEVEL)
    _first(out, _bad_stamp(values), STAMP)
    return out


def squeal_refusals(values: Any) -> np.ndarray:
    """Why each SquealPrediction is unusable ('' when usable): its stamp, its risk."""
    out = np.full(len(values.risk), "", object)
    _first(out, _bad_stamp(values), STAMP)
    _first(out, values.risk > RISK_HIGH, RISK)
    return out


def predictions(values: Any, rows: np.ndarray) -> list[Predicted]:
    """RollingNoise (or SquealPrediction: its risk) at rows as the predictions measurements are paired with."""
    stamps, ids = time_columns_ns(values.header.stamp).tolist(), values.train_id
    if hasattr(values, "risk"):
        risk = values.risk.tolist()
        return [Predicted(stamps[i], ids[i], SQUEAL, np.zeros(0), float("nan"), float("nan"), float("nan"), risk[i])
                for i in rows.tolist()]
    eq, fmax, tel = (np.asarray(getattr(values, k), float).tolist() for k in ("lpaeq_tp_dba", "lpafmax_dba", "tel_dba"))
    return [Predicted(stamps[i], ids[i], values.model[i], np.array(values.lp_db[i], float), eq[i], fmax[i], tel[i])
            for i in rows.tolist()]


def corrugation(values: Any, i: int) -> Corrugation:
    """The bands and amplitudes of state i (a usable one); a state without post-grinding amplitudes
    counts growth from zero."""
    amp = np.asarray(values.amplitude_m[i], float)
    post = np.asarray(values.post_grinding_m[i], float)
    return Corrugation(np.asarray(values.wavelength_m[i], float), amp, post if len(post) else np.zeros_like(amp))


def band_runs(values: Any, rows: np.ndarray) -> list[np.ndarray]:
    """The states at rows in runs, in order, each on the same bands and thresholds as its first."""
    wl, thr = values.wavelength_m, values.threshold_m
    if isinstance(wl, np.ndarray) and isinstance(thr, np.ndarray):
        w, t = wl[rows], thr[rows]
        new = np.ones(len(rows), bool)
        new[1:] = np.any(w[1:] != w[:-1], axis=1) | np.any(t[1:] != t[:-1], axis=1)
        starts = np.flatnonzero(new)
        return np.split(rows, starts[1:])
    out: list[list[int]] = []
    for i in rows.tolist():
        if out and np.array_equal(wl[i], wl[out[-1][0]]) and np.array_equal(thr[i], thr[out[-1][0]]):
            out[-1].append(i)
        else:
            out.append([i])
    return [np.array(r, np.intp) for r in out]


def corrugation_series(values: Any, rows: np.ndarray) -> dict[str, np.ndarray]:
    """States at rows on the same bands as AlertManager.on_states' arguments: stamps [ns], bands [m]
    and thresholds [m] of the first, amplitudes [m] (states x bands), forecast fields per state."""
    first = int(rows[0])
    amp = values.amplitude_m
    return {"stamp_ns": time_columns_ns(values.header.stamp)[rows],
            "wavelength_m": np.asarray(values.wavelength_m[first]),
            "amplitude_m": amp[rows] if isinstance(amp, np.ndarray) else np.array([amp[i] for i in rows.tolist()]),
            "threshold_m": np.asarray(values.threshold_m[first]),
            "days_to_threshold": np.asarray(values.days_to_threshold)[rows],
            "grinding_due": np.asarray(values.grinding_due)[rows],
            "grinding_due_ns": time_columns_ns(values.grinding_due_time)[rows]}
