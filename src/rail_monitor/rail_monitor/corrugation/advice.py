"""Speed distributions against a corrugation state: the growth of a what-if distribution, and
the speed advice.

The expected log growth per pass of a band component under a speed distribution p(V) is
g = sum_V p(V) ln|1 + K_b F^2 H(V / lambda)| (the paper's eq. 2; docs/models.md, "Speed
distributions"). The advice is the distribution with the current mean speed, within the advice
limits, whose peak g over the bands is least (:func:`rail_monitor.models.corrugation.
optimise_speed_distribution`).
"""

from __future__ import annotations

import numpy as np

from rail_monitor.core.passes import FRICTION_NAMES, MAX_SPEED_MPS
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Advice, Evaluation
from rail_monitor.models import corrugation as cg


def traffic_mix(est: CorrugationEstimator, friction_state: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(class index, friction state, axle weight) of the traffic mix: the kept passes', or the
    site's class shares with dry rail when there are none; friction_state > 0 fixes it."""
    k = est.kept
    if len(k):
        pairs = np.stack([k.class_idx, k.friction])
        keys, inverse = np.unique(pairs, axis=1, return_inverse=True)
        weight = np.bincount(inverse.ravel(), weights=k.axles)
        cls, fr = keys
    else:
        vs = [est.site.vehicle(c) for c in est.tables.classes]
        cls = np.arange(len(vs))
        fr = np.ones(len(vs), np.int64)
        weight = np.array([v.traffic_share * v.mean_axles_per_train for v in vs])
    if friction_state:
        fr = np.full_like(fr, friction_state)
    return cls, fr, weight / weight.sum()


def growth_at_speeds(est: CorrugationEstimator, speeds: np.ndarray, friction_state: int = 0) -> np.ndarray:
    """g per component (B, P, S) [1/axle pass] at each speed [m/s] for the traffic mix."""
    cls, fr, w = traffic_mix(est, friction_state)
    s = np.asarray(speeds, float)
    per = est.tables.at(np.repeat(cls, len(s)), np.repeat(fr, len(s)), np.tile(s, len(cls)))
    return np.einsum("m,msbp->bps", w, per.reshape(len(cls), len(s), *per.shape[1:]))


def evaluate(est: CorrugationEstimator, speeds: np.ndarray, probability: np.ndarray, friction_state: int = 0,
             passes_per_day: float = 0.0) -> Evaluation:
    """Growth per band of a what-if speed distribution (speeds [m/s], probabilities), and what it
    does to the forecast; ValueError for an unusable distribution."""
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
    g = growth_at_speeds(est, v, friction_state) @ (p / p.sum())
    current = est.recent_growth().max() if len(est.kept) else np.nan
    band_g = g.max(axis=1)
    peak = float(band_g.max())
    fc = est.forecast(g, passes_per_day or None)
    return Evaluation(band_g, peak, float(est.bands[int(np.argmax(band_g))]),
                      float(current / peak) if peak > 0 else float("inf"), fc.days_to_threshold)


def advise(est: CorrugationEstimator, speeds: np.ndarray | None = None, weights: np.ndarray | None = None,
           friction_state: int = 0) -> Advice:
    """The distribution with the current mean speed, within the advice limits, with the least peak g.

    Current distribution: the kept passes (axle-weighted), or the given speeds [m/s] with
    weights; the traffic mix is the kept one unless friction_state fixes it.
    """
    k = est.kept
    recent = speeds is None
    if recent:
        if len(k) == 0:
            raise ValueError("no recent passes to advise on")
        speeds, weights = k.speed, k.axles.astype(float)
    v = np.asarray(speeds, float)
    w = np.ones_like(v) if weights is None else np.asarray(weights, float)
    classes = est.site.vehicles.values()
    lo = est.cfg.advice_min_speed_mps or min(c.speed_min_mps for c in classes)
    hi = est.cfg.advice_max_speed_mps or max(c.speed_max_mps for c in classes)
    width = est.cfg.advice_bin_mps
    edges = np.arange(lo, hi + 0.5 * width, width)
    centres = 0.5 * (edges[:-1] + edges[1:])
    current_p = np.histogram(np.clip(v, lo, hi), edges, weights=w)[0]
    current_p /= current_p.sum()
    mean = float(np.clip(np.average(v, weights=w), centres[0], centres[-1]))
    grid = growth_at_speeds(est, centres, friction_state)
    best = cg.optimise_speed_distribution(grid.reshape(-1, len(centres)), centres, mean, est.cfg.advice_max_share)
    # Each kept pass with its own class and friction; a given distribution with the mix.
    g_now = (est.recent_growth() if recent and not friction_state
             else growth_at_speeds(est, v, friction_state) @ (w / w.sum())).max(axis=1)
    cur_peak = float(g_now.max())
    rec = min(best.peak_growth, cur_peak)
    return Advice(mean, float(lo), float(hi), centres, current_p, best.probability, cur_peak, rec,
                  1.0 - rec / cur_peak if cur_peak > 0 else 0.0,
                  cur_peak / rec if rec > 0 else float("inf"), float(est.bands[int(np.argmax(g_now))]))


def advise_or_none(est: CorrugationEstimator) -> Advice | None:
    """The advice on the kept passes, or None when there is nothing to advise on."""
    if not len(est.kept):
        return None
    try:
        return advise(est)
    except ValueError:
        return None
