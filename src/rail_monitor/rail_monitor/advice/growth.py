"""Speed distributions against a corrugation state: the growth of a what-if distribution.

The expected log growth per pass of a band component under a speed distribution p(V) is
g = sum_V p(V) ln|1 + K_b F^2 H(V / lambda)| (the paper's eq. 2; docs/models.md, "Speed
distributions"). The speed advice, which also weighs noise and squeal, is
:mod:`rail_monitor.advice.plan`.
"""

from __future__ import annotations

import numpy as np

from rail_monitor.core.contact import contact_state_of
from rail_monitor.core.passes import FRICTION_DRY, FRICTION_NAMES, MAX_SPEED_MPS
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Evaluation


def traffic_mix(est: CorrugationEstimator, friction_state: int = 0,
                vehicle_class: str | None = None) -> tuple[np.ndarray, ...]:
    """(class index, friction state, contact regime, axle weight) of the traffic mix: the kept
    passes' (only vehicle_class's when given), or without them the site's classes weighted by
    traffic share and axles per train (only vehicle_class when given), on dry rail in partial slip;
    friction_state > 0 puts every pass in that state, each in the regime its load and creepage then
    give (rail_monitor.core.contact)."""
    k = est.kept
    rows = np.ones(len(k), bool) if not vehicle_class or not len(k) else \
        k.class_idx == est.tables.classes.index(vehicle_class)
    if rows.any():
        fr, regime = k.friction[rows], k.regime[rows]
        if friction_state:
            fr = np.full_like(fr, friction_state)
            regime = contact_state_of(est.site, np.array(est.tables.classes, object)[k.class_idx[rows]], fr,
                                      k.load[rows], k.creepage[rows], k.speed[rows]).regime.astype(np.int64)
        keys, inverse = np.unique(np.stack([k.class_idx[rows], fr, regime]), axis=1, return_inverse=True)
        weight = np.bincount(inverse.ravel(), weights=k.axles[rows])
        cls, fr, regime = keys
    else:
        names = [vehicle_class] if vehicle_class else est.tables.classes
        vs = [est.site.vehicle(c) for c in names]
        cls = est.tables.class_index(np.array(names, object))
        fr = np.full(len(vs), friction_state or FRICTION_DRY, np.int64)
        regime = np.zeros(len(vs), np.int64)
        weight = np.array([(1.0 if vehicle_class else v.traffic_share) * v.mean_axles_per_train for v in vs])
    return cls, fr, regime, weight / weight.sum()


def growth_at_speeds(est: CorrugationEstimator, speeds: np.ndarray, friction_state: int = 0,
                     vehicle_class: str | None = None) -> np.ndarray:
    """g per component (B, P, S) [1/axle pass] at each speed [m/s] for the traffic mix."""
    cls, fr, regime, w = traffic_mix(est, friction_state, vehicle_class)
    s = np.asarray(speeds, float)
    per = est.tables.at(np.repeat(cls, len(s)), np.repeat(fr, len(s)), np.repeat(regime, len(s)), np.tile(s, len(cls)))
    return np.einsum("m,msbp->bps", w, per.reshape(len(cls), len(s), *per.shape[1:]))


def axles_per_train(est: CorrugationEstimator, vehicle_class: str | None = None) -> float | None:
    """Axles per train of a what-if without kept passes: the class's when given, else None (the
    forecast's default: the kept passes', or the site's traffic-weighted mean)."""
    return est.site.vehicle(vehicle_class).mean_axles_per_train if vehicle_class and not len(est.kept) else None


def evaluate(est: CorrugationEstimator, speeds: np.ndarray, probability: np.ndarray, friction_state: int = 0,
             passes_per_day: float = 0.0, vehicle_class: str | None = None) -> Evaluation:
    """Growth per band of a what-if speed distribution (speeds [m/s], probabilities), and what it
    does to the forecast; ValueError for an unusable distribution. Without kept passes the kernel
    is that of vehicle_class when given, else the site's traffic mix (:func:`traffic_mix`)."""
    v, p = np.asarray(speeds, float), np.asarray(probability, float)
    if v.shape != p.shape or v.ndim != 1 or len(v) == 0:
        raise ValueError("speed_mps and probability must be 1-D, non-empty and the same length")
    if not (np.all(np.isfinite(v)) and np.all((v > 0) & (v <= MAX_SPEED_MPS))):
        raise ValueError(f"speeds must be in (0, {MAX_SPEED_MPS:g}] m/s")
    if not (np.all(np.isfinite(p)) and np.all(p >= 0) and p.sum() > 0):
        raise ValueError("probabilities must be finite, non-negative and not all zero")
    if friction_state not in (0, *FRICTION_NAMES):
        raise ValueError(f"friction_state {friction_state} unknown")
    if not (np.isfinite(passes_per_day) and passes_per_day >= 0):
        raise ValueError("passes_per_day must be finite and not negative (0: the recent traffic)")
    g = growth_at_speeds(est, v, friction_state, vehicle_class) @ (p / p.sum())
    current = est.recent_growth().max() if len(est.kept) else np.nan
    band_g = g.max(axis=1)
    peak = float(band_g.max())
    fc = est.forecast(g, passes_per_day or None, axles_per_train(est, vehicle_class))
    return Evaluation(band_g, peak, float(est.bands[int(np.argmax(band_g))]),
                      float(current / peak) if peak > 0 else float("inf"), fc.days_to_threshold)
