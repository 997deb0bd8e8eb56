"""Speed advice per vehicle class: shares of each class's trains in speed bands an operator can
publish ("emu 60-70 km/h: 40 %"), at each class's recent mean speed, that cut the peak corrugation
growth without raising the pass-weighted mean rolling noise by more than a limit or the share of
passes at a squeal risk (:func:`rail_monitor.advice.speed_plan.optimise_speed_plan`).

Bands are ``advice_band_kmh`` wide on a grid from 0, clipped to each class's speed range (its
speed_min/speed_max, within the advice's limits); a band's growth, noise and squeal are averaged
over speeds across it, since trains told "60-70 km/h" run anywhere in it. The traffic is the
kept passes: each class's friction states and contact regimes (axle-weighted) for the growth,
its passes' angles of attack, loads and friction for squeal. Shares are of each class's passes
(trains); the growth weighs the classes by their axle passes. Current and advised distributions
are evaluated by the same band model, so the cut and the interval factor compare like with like.
"""

from __future__ import annotations

from concurrent.futures import Executor
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from rail_monitor.advice.consequences import Consequences
from rail_monitor.advice.growth import growth_at_speeds
from rail_monitor.advice.speed_plan import SpeedPlan, optimise_speed_plan, plan_growth
from rail_monitor.core.passes import KMH_PER_MPS
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.noise.records import Corrugation

POINTS_PER_BAND = 5  # speeds across a band over which its growth, noise and squeal are averaged


@dataclass(frozen=True)
class SpeedAdvice:
    """Speed advice (units and meaning as in rail_msgs/SpeedAdvisory, whose fields these are)."""

    mean_speed_mps: float
    min_speed_mps: float
    max_speed_mps: float
    speed_bin_centres_mps: np.ndarray
    current_probability: np.ndarray
    recommended_probability: np.ndarray
    current_peak_growth: float
    recommended_peak_growth: float
    peak_growth_reduction: float
    grinding_interval_factor: float
    current_peak_wavelength_m: float
    vehicle_class: list[str]
    class_mean_speed_mps: np.ndarray
    class_pass_share: np.ndarray
    class_squeal_share_current: np.ndarray
    class_squeal_share_recommended: np.ndarray
    noise_model: list[str]
    class_noise_current_dba: np.ndarray      # (classes x models), row-major
    class_noise_recommended_dba: np.ndarray
    noise_current_dba: np.ndarray            # per model
    noise_recommended_dba: np.ndarray
    noise_rise_limit_dba: float
    squeal_share_current: float
    squeal_share_recommended: float
    band_vehicle_class: list[str]
    band_low_mps: np.ndarray
    band_high_mps: np.ndarray
    band_current_share: np.ndarray
    band_recommended_share: np.ndarray

    def noise_change(self, c: int | None = None) -> np.ndarray:
        """Change of the mean LpAFmax per noise model [dB(A)]: of class index c, or of every class."""
        if c is None:
            return self.noise_recommended_dba - self.noise_current_dba
        m = len(self.noise_model)
        return self.class_noise_recommended_dba[c * m:(c + 1) * m] - self.class_noise_current_dba[c * m:(c + 1) * m]

    def band_label(self, i: int) -> str:
        """Band row i in km/h, as an operator signs it ("60-70")."""
        return f"{KMH_PER_MPS * self.band_low_mps[i]:.0f}-{KMH_PER_MPS * self.band_high_mps[i]:.0f}"

    def lines(self) -> list[str]:
        """The plan for people: one line per class, then the consequences."""
        def noise(change: np.ndarray) -> str:
            return ", ".join(f"{m} {d:+.2f}" for m, d in zip(self.noise_model, change, strict=True))

        out = []
        for c, name in enumerate(self.vehicle_class):
            rows = [i for i, n in enumerate(self.band_vehicle_class)
                    if n == name and self.band_recommended_share[i] > 5e-3]
            bands = ", ".join(f"{self.band_label(i)} km/h {100 * self.band_recommended_share[i]:.0f} %" for i in rows)
            out.append(f"{name} (mean {KMH_PER_MPS * self.class_mean_speed_mps[c]:.0f} km/h): {bands}; noise "
                       f"{noise(self.noise_change(c))} dB(A); squealing {100 * self.class_squeal_share_current[c]:.1f}"
                       f" -> {100 * self.class_squeal_share_recommended[c]:.1f} %")
        out.append(f"peak growth -{100 * self.peak_growth_reduction:.0f} %, grinding interval "
                   f"x{self.grinding_interval_factor:.2f}; mean noise {noise(self.noise_change())} dB(A) (limit "
                   f"+{self.noise_rise_limit_dba:g}); squealing passes {100 * self.squeal_share_current:.1f} -> "
                   f"{100 * self.squeal_share_recommended:.1f} %")
        return out


def advice_of_message(msg: Any) -> SpeedAdvice:
    """A SpeedAdvice from a decoded rail_msgs/SpeedAdvisory (its fields are the record's)."""
    values = {}
    for f in fields(SpeedAdvice):
        v = getattr(msg, f.name)
        values[f.name] = [str(x) for x in v] if f.type == "list[str]" else \
            np.asarray(v, float) if f.type == "np.ndarray" else float(v)
    return SpeedAdvice(**values)


def _bands(est: CorrugationEstimator, classes: list[str], band_kmh: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Common band edges (S + 1,) [m/s] and each class's band limits (C, S) low, high [m/s]: the
    grid clipped to the class's speed range, a clipped end under half a band wide joined to its
    neighbour (nobody publishes "60-60.1 km/h"); low == high for a band the class does not use."""
    cfg = est.cfg
    width = band_kmh / KMH_PER_MPS
    lo = np.array([max(est.site.vehicle(c).speed_min_mps, cfg.advice_min_speed_mps) for c in classes])
    hi = np.array([min(est.site.vehicle(c).speed_max_mps, cfg.advice_max_speed_mps or np.inf) for c in classes])
    if np.any(hi <= lo):
        raise ValueError("a class's speed range lies outside the advice's speed limits")
    edges = np.arange(np.floor(lo.min() / width), np.ceil(hi.max() / width) + 1) * width
    low = np.clip(edges[None, :-1], lo[:, None], hi[:, None])
    high = np.clip(edges[None, 1:], lo[:, None], hi[:, None])
    for c in range(len(classes)):
        used = np.flatnonzero(high[c] > low[c])
        if len(used) > 1 and high[c, used[-1]] - low[c, used[-1]] < 0.5 * width:
            high[c, used[-2]], low[c, used[-1]] = high[c, used[-1]], high[c, used[-1]]
        if len(used) > 1 and high[c, used[0]] - low[c, used[0]] < 0.5 * width:
            low[c, used[1]], high[c, used[0]] = low[c, used[0]], low[c, used[0]]
    return edges, low, high


def _points(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Speeds across each band (C, S, POINTS_PER_BAND) [m/s]: midpoints of equal slices."""
    u = (np.arange(POINTS_PER_BAND) + 0.5) / POINTS_PER_BAND
    return low[..., None] + (high - low)[..., None] * u


@dataclass(frozen=True)
class AdviceProblem:
    """The advice's linear programme for the kept passes (advice.speed_plan), with what the advice
    reports of it. C classes, S bands, R band components, M noise models."""

    classes: list[str]
    present: np.ndarray      # (C,) the classes' indices in the growth tables
    edges: np.ndarray        # (S + 1,) band grid [m/s]
    low: np.ndarray          # (C, S) each class's band limits [m/s] (low == high: not used)
    high: np.ndarray
    allowed: np.ndarray      # (C, S) bool
    growth: np.ndarray       # (C, R, S) [1/axle pass]
    noise: np.ndarray        # (M, C, S) LpAFmax [dB(A)]
    squeal: np.ndarray       # (C, S) share of passes at a squeal risk [-]
    current: np.ndarray      # (C, S) shares of each class's recent passes [-]
    pass_weight: np.ndarray  # (C,) each class's share of the passes
    axle_weight: np.ndarray  # (C,) each class's share of the axle passes
    mean: np.ndarray         # (C,) each class's mean speed, kept [m/s]
    cap: np.ndarray          # (C,) largest share in one band [-]
    limits: list[tuple[np.ndarray, float]]  # noise (per model), then squeal: (A (C, S), b) with A p <= b

    @property
    def centres(self) -> np.ndarray:
        return 0.5 * (self.low + self.high)

    def solve(self, cap: np.ndarray | None = None, limits: list[tuple[np.ndarray, float]] | None = None) -> SpeedPlan:
        """The plan of least peak growth, under the problem's cap and limits or those given."""
        return optimise_speed_plan(self.growth, self.axle_weight, self.centres, self.allowed, self.mean,
                                   self.cap if cap is None else cap, self.limits if limits is None else limits)


def advice_problem(est: CorrugationEstimator, consequences: Consequences, pool: Executor | None = None,
                   band_kmh: float | None = None) -> AdviceProblem:
    """The advice's programme for the kept passes (ValueError when there are none); band_kmh: the
    band width (default the site's advice_band_kmh); pool: threads for the classes' growth, noise
    and squeal on their speed points (independent, so the split changes no number)."""
    k = est.kept
    if not len(k):
        raise ValueError("no recent passes to advise on")
    cfg = est.cfg
    present = np.unique(k.class_idx)
    classes = [est.tables.classes[i] for i in present]
    edges, low, high = _bands(est, classes, band_kmh or cfg.advice_band_kmh)
    allowed = high > low + 1e-9
    pts = _points(low, high)
    nc, ns = low.shape
    state = Corrugation(est.bands, est.amplitude, est.grinding_amplitude)

    def on_points(c: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Class c's growth (R, S), noise (M, S) and squeal share (S,), each the mean over its points."""
        speeds = pts[c].ravel()
        mixed = growth_at_speeds(est, speeds, vehicle_class=classes[c])                 # (B, P, S x points)
        return (mixed.reshape(-1, ns, POINTS_PER_BAND).mean(axis=2),
                consequences.noise_dba([classes[c]], speeds, state)[:, 0].reshape(-1, ns, POINTS_PER_BAND)
                .mean(axis=2),
                consequences.squeal_share(k, classes[c], present[c], speeds).reshape(ns, POINTS_PER_BAND).mean(axis=1))

    growth, noise, squeal_share = zip(*(pool.map if pool is not None else map)(on_points, range(nc)), strict=True)
    passes = np.zeros(nc)
    axles = np.zeros(nc)
    current = np.zeros((nc, ns))
    for c, ci in enumerate(present):
        rows = k.class_idx == ci
        passes[c], axles[c] = rows.sum(), k.axles[rows].sum()
        used = np.flatnonzero(allowed[c])
        v = np.clip(k.speed[rows], low[c, used[0]], high[c, used[-1]])
        band = used[np.clip(np.searchsorted(low[c, used], v, side="right") - 1, 0, len(used) - 1)]
        current[c] = np.bincount(band, minlength=ns) / passes[c]
    lp = np.stack(noise, axis=1)               # (M, C, S)
    sq = np.stack(squeal_share)                # (C, S)
    mean = (current * 0.5 * (low + high)).sum(axis=1)
    pass_w, axle_w = passes / passes.sum(), axles / axles.sum()
    cap = np.maximum.reduce([np.full(nc, cfg.advice_max_share), 1.0 / allowed.sum(axis=1), current.max(axis=1)])
    limits = [(pass_w[:, None] * lp[m], float((pass_w[:, None] * lp[m] * current).sum()) + cfg.advice_noise_rise_dba)
              for m in range(len(lp))]
    limits.append((pass_w[:, None] * sq, float((pass_w[:, None] * sq * current).sum()) + 1e-12))
    return AdviceProblem(classes=classes, present=present, edges=edges, low=low, high=high, allowed=allowed,
                         growth=np.stack(growth), noise=lp, squeal=sq, current=current, pass_weight=pass_w,
                         axle_weight=axle_w, mean=mean, cap=cap, limits=limits)


def advise(est: CorrugationEstimator, consequences: Consequences, pool: Executor | None = None,
           problem: AdviceProblem | None = None) -> SpeedAdvice:
    """The plan for the kept passes (ValueError when there are none, or no plan fits the limits);
    pool: as for advice_problem; problem: the kept passes' advice_problem where the caller has it."""
    p = problem or advice_problem(est, consequences, pool)
    plan = p.solve()
    g, lp, sq, current, pass_w, low, high = p.growth, p.noise, p.squeal, p.current, p.pass_weight, p.low, p.high
    now = plan_growth(g, p.axle_weight, current)
    cur_peak, rec_peak = float(now.max()), min(plan.peak_growth, float(now.max()))
    rec = plan.share
    per_band = g.shape[1] // len(est.bands)
    show = p.allowed & ((current > 1e-6) | (rec > 1e-6))
    ci_rows = np.nonzero(show)[0]
    class_noise_current, class_noise_rec = (lp * current).sum(axis=2), (lp * rec).sum(axis=2)
    class_squeal_current, class_squeal_rec = (sq * current).sum(axis=1), (sq * rec).sum(axis=1)
    classes, mean, edges = p.classes, p.mean, p.edges
    return SpeedAdvice(
        mean_speed_mps=float(pass_w @ mean), min_speed_mps=float(low.min()), max_speed_mps=float(high.max()),
        speed_bin_centres_mps=0.5 * (edges[:-1] + edges[1:]),
        current_probability=pass_w @ current, recommended_probability=pass_w @ rec,
        current_peak_growth=cur_peak, recommended_peak_growth=rec_peak,
        peak_growth_reduction=1.0 - rec_peak / cur_peak if cur_peak > 0 else 0.0,
        grinding_interval_factor=cur_peak / rec_peak if rec_peak > 0 else float("inf"),
        current_peak_wavelength_m=float(est.bands[int(np.argmax(now)) // per_band]),
        vehicle_class=classes, class_mean_speed_mps=mean, class_pass_share=pass_w,
        class_squeal_share_current=class_squeal_current, class_squeal_share_recommended=class_squeal_rec,
        noise_model=list(consequences.noise.models),
        class_noise_current_dba=class_noise_current.T.ravel(), class_noise_recommended_dba=class_noise_rec.T.ravel(),
        noise_current_dba=class_noise_current @ pass_w, noise_recommended_dba=class_noise_rec @ pass_w,
        noise_rise_limit_dba=est.cfg.advice_noise_rise_dba,
        squeal_share_current=float(pass_w @ class_squeal_current),
        squeal_share_recommended=float(pass_w @ class_squeal_rec),
        band_vehicle_class=[classes[c] for c in ci_rows], band_low_mps=low[show], band_high_mps=high[show],
        band_current_share=current[show], band_recommended_share=rec[show])


def advise_or_none(est: CorrugationEstimator, consequences: Consequences,
                   pool: Executor | None = None) -> SpeedAdvice | None:
    """The advice on the kept passes, or None when there is nothing to advise on or no plan fits."""
    try:
        return advise(est, consequences, pool)
    except ValueError:
        return None


@dataclass(frozen=True)
class SideEffects:
    """What a site-wide speed distribution does to noise and squeal against the recent passes
    (units as in rail_srvs EvaluateSpeedDistribution's response)."""

    noise_model: list[str]
    noise_change_dba: np.ndarray      # per model [dB(A)]
    squeal_share_current: float
    squeal_share: float


GRID_STEP_MPS = 0.5  # speed grid of the side effects, interpolated linearly


def evaluate_consequences(est: CorrugationEstimator, consequences: Consequences, speeds: np.ndarray,
                          probability: np.ndarray) -> SideEffects:
    """Noise and squeal of every class at the distribution (speeds [m/s], weights) against the
    kept passes at their own speeds, both on one speed grid per class (ValueError without kept
    passes)."""
    k = est.kept
    if not len(k):
        raise ValueError("no recent passes to compare with")
    v = np.asarray(speeds, float)
    p = np.asarray(probability, float) / np.sum(probability)
    state = Corrugation(est.bands, est.amplitude, est.grinding_amplitude)
    models = list(consequences.noise.models)
    noise_now, noise_new = np.zeros(len(models)), np.zeros(len(models))
    sq_now = sq_new = 0.0
    for ci in np.unique(k.class_idx):
        rows = k.class_idx == ci
        share = rows.mean()
        name = est.tables.classes[ci]
        lo, hi = min(v.min(), k.speed[rows].min()), max(v.max(), k.speed[rows].max())
        grid = np.arange(lo, hi + GRID_STEP_MPS, GRID_STEP_MPS)
        lp = consequences.noise_dba([name], grid, state)[:, 0]               # (M, G)
        sq = consequences.squeal_share(k, name, ci, grid)                    # (G,)
        for m in range(len(models)):
            noise_now[m] += share * np.interp(k.speed[rows], grid, lp[m]).mean()
            noise_new[m] += share * p @ np.interp(v, grid, lp[m])
        sq_now += share * float(consequences.squeal_share(k, name, ci, None)[0])
        sq_new += share * p @ np.interp(v, grid, sq)
    return SideEffects(models, noise_new - noise_now, float(sq_now), float(sq_new))

