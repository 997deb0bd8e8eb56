"""The grinding forecast: time to the intervention threshold of each band, and the recent traffic.

For one component, passes to threshold = ln(Z_threshold / Z) / g per axle pass; for a band,
the energy sum of its components (:func:`rail_monitor.models.corrugation_state.passes_to_band_level`);
days = train passes / train passes per day (docs/models.md, "Grinding forecast").
"""

from __future__ import annotations

import numpy as np

from rail_monitor.core.friction import FRICTION_DRY, FRICTION_MODIFIER
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.corrugation.history import KeptPasses
from rail_monitor.corrugation.records import Forecast, ForecastInterval
from rail_monitor.models import calibration
from rail_monitor.models import corrugation_state as cstate
from rail_monitor.models.engine import corrugation_kernels

# Forecasts further out than a century get no date (0): a band that barely grows (full-sliding
# passes nearly balancing the others) can be 1e12 days away, past any 64-bit time stamp.
MAX_DATED_DAYS = 36_525.0
INTERVAL_DRAWS = 500  # draws of the forecast interval: its quantiles to about +-2 % of the spread
INTERVAL_SEED = 20_260_901


def forecasts(log_components: np.ndarray, growth: np.ndarray, rate: np.ndarray, axles: np.ndarray,
              newest_ns: np.ndarray, threshold: np.ndarray, lead_time_days: float,
              fallback_axles: float, engine: str = "numpy",
              log_amplitude: np.ndarray | None = None, growth_max: np.ndarray | None = None) -> Forecast:
    """The forecast of N states at once: ln Z and g (N, B, P) [ln m, 1/axle pass], train passes per
    day and axles per train (N,) (NaN axles: ``fallback_axles``), newest pass time (N,) [ns],
    band thresholds (B,) [m]; a Forecast of arrays (grinding_due_ns 0: no date, the forecast
    being infinite or beyond MAX_DATED_DAYS). engine: of the per-band reductions and of the first
    band to its threshold (numpy, or numba: models.corrugation_jit); log_amplitude: ln of each band's r.m.s.
    (N, B), and growth_max: g's largest component per band (N, B), when the caller has them."""
    kernels = corrugation_kernels(engine)
    axles = np.where(np.isfinite(axles), axles, fallback_axles)
    log_threshold = np.log(threshold)
    if log_amplitude is None:
        log_amplitude = kernels.band_log_amplitude(log_components)
    margin = log_threshold - log_amplitude
    band, axle_passes = kernels.first_band_to_level(log_components, growth, log_threshold)
    worst = np.where(np.isfinite(axle_passes), band, np.argmin(margin, axis=1))
    passes = axle_passes / axles
    with np.errstate(divide="ignore", invalid="ignore"):
        days = np.where(np.isfinite(rate) & (rate > 0), passes / rate, np.inf)
    days = np.where(passes == 0.0, 0.0, days)
    due = (margin.min(axis=1) <= 0) | (days <= lead_time_days)
    dated = days <= MAX_DATED_DAYS
    ahead_ns = (np.where(dated, days, 0.0) * NS_PER_DAY).astype(np.int64)  # truncated toward zero, as int() does
    due_ns = np.where(dated, np.asarray(newest_ns, np.int64) + ahead_ns, 0)
    return Forecast(growth.max(axis=2) if growth_max is None else growth_max, worst, passes, days, rate, due, due_ns)


def single(fc: Forecast) -> Forecast:
    """Row 0 of a Forecast of arrays, as scalars."""
    return Forecast(fc.growth_per_axle_pass[0], int(fc.worst_band[0]), float(fc.passes_to_threshold[0]),
                    float(fc.days_to_threshold[0]), float(fc.passes_per_day[0]), bool(fc.grinding_due[0]),
                    int(fc.grinding_due_ns[0]))


def traffic(kept: KeptPasses, min_traffic_days: float) -> tuple[float, float]:
    """Recent traffic: (train passes per day, axles per train); NaN rate with fewer than 2 passes or
    over less than min_traffic_days [day]."""
    if len(kept) == 0:
        return float("nan"), float("nan")
    span = (int(kept.stamp_ns.max()) - int(kept.stamp_ns.min())) / NS_PER_DAY
    rate = (len(kept) - 1) / span if span > 0 and span >= min_traffic_days else float("nan")
    return rate, float(kept.axles.mean())


def interval(log_components: np.ndarray, growth_since_survey: np.ndarray, growth_by_state: np.ndarray,
             posterior: calibration.KbPosterior, level_cov: np.ndarray, cross: np.ndarray, threshold: np.ndarray,
             days_per_axle_pass: float, newest_ns: int, season: np.ndarray | None = None) -> ForecastInterval:
    """P10, P50 and P90 of the days to threshold, per band and of the first band, over the
    uncertainty of K_b and of the present roughness.

    ln Z (B, P) [ln m]; the log growth since the last survey per friction state (4, B, P), computed
    at the posterior median; the recent growth per friction state (4, B, P) [1/axle pass]; the
    covariance of the bands' ln Z at the last survey (level_cov (B, B) [-]) and with ln K_b (cross
    (B, 4)); thresholds (B,) [m]; days per axle pass at the recent traffic. Each of INTERVAL_DRAWS
    fixed draws takes ln K_b and each band's level error jointly from that covariance and the
    posterior's (both growths scale with exp(delta_f), first order in K_b), and is forecast as the
    state is; the quantiles are those of the draws (so the
    same state gives the same interval in every process). The traffic and its friction mix are
    the recent window's, or with season (the log growth per day and friction state of the year
    before the newest pass, (365, 4, B, P), at the posterior median) that year's repeated: day j
    ahead grows as day j a year earlier did, day by day through the first year, then at that
    year's mean per day.
    """
    rng = np.random.Generator(np.random.PCG64(INTERVAL_SEED))
    bands = len(threshold)
    draws = rng.standard_normal((INTERVAL_DRAWS, bands + len(posterior.mean))) @ _root(
        calibration.joint_cov(level_cov, cross, posterior.cov)).T
    level, delta = draws[:, :bands], draws[:, bands:]
    state = log_components + np.einsum("df,fbp->dbp", np.expm1(delta), growth_since_survey) + level[:, :, None]
    if season is not None:
        days = _seasonal_days(state, np.exp(delta), season, np.log(threshold))
    else:
        growth = np.einsum("df,fbp->dbp", np.exp(delta), growth_by_state)
        axle_passes = cstate.passes_to_band_level(state, growth, np.log(threshold))
        with np.errstate(invalid="ignore"):
            days = np.where(axle_passes == 0.0, 0.0, axle_passes * days_per_axle_pass)
    q = (0.1, 0.5, 0.9)
    first = np.quantile(days.min(axis=1), q, method="inverted_cdf")
    due = np.array([newest_ns + int(d * NS_PER_DAY) if d <= MAX_DATED_DAYS else 0 for d in first.tolist()], np.int64)
    return ForecastInterval(np.quantile(days, q, axis=0, method="inverted_cdf"), first, due,
                            "recent" if season is None else "season")


def _root(cov: np.ndarray) -> np.ndarray:
    """A matrix R with R R^T = cov: its Cholesky factor, or for a covariance only semi-definite (a
    level known exactly) the eigenvectors scaled by the roots of their non-negative eigenvalues."""
    try:
        return np.linalg.cholesky(cov)
    except np.linalg.LinAlgError:
        w, v = np.linalg.eigh(cov)
        return v * np.sqrt(np.clip(w, 0.0, None))


def with_friction_modifier(growth_by_state: np.ndarray, dry_as_modifier: np.ndarray, season: np.ndarray | None,
                           k_b: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """The recent growth per friction state (4, B, P) [1/axle pass] and the season's (S, 4, B, P,
    per unit K_b) with a friction modifier applied where the rail was dry: the dry passes' growth
    moves to the friction-modifier state as those passes give it there (dry_as_modifier (B, P), per
    axle pass of all kept passes), so the interval draws it with the modifier's K_b posterior. The
    season keeps no passes to recompute: its dry days move by the recent ratio of each component's
    growth with the modifier to without, per unit K_b (1 where no recent pass was dry)."""
    dry, fm = FRICTION_DRY - 1, FRICTION_MODIFIER - 1
    growth = growth_by_state.copy()
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(growth[dry] != 0, dry_as_modifier * k_b[dry] / (growth[dry] * k_b[fm]), 1.0)
    growth[fm] += dry_as_modifier
    growth[dry] = 0.0
    if season is not None:
        season = season.copy()
        season[:, fm] += season[:, dry] * ratio
        season[:, dry] = 0.0
    return growth, season


def _seasonal_days(state: np.ndarray, scale: np.ndarray, season: np.ndarray, log_threshold: np.ndarray,
                   block: int = 25) -> np.ndarray:
    """Days to each band's threshold (D, B) of D states ln Z (D, B, P) growing day by day as the
    season's days (S, 4, B, P), each friction state's growth scaled per draw (D, 4); past the
    season, at its mean per day. Within a day the level is interpolated linearly in ln Z."""
    out = np.empty(state.shape[:2])
    year = season.sum(axis=0)                                         # (4, B, P)
    for lo in range(0, len(state), block):
        s, k = state[lo:lo + block], scale[lo:lo + block]
        daily = np.einsum("df,jfbp->djbp", k, season)                 # (d, S, B, P)
        path = s[:, None] + np.cumsum(daily, axis=1)
        level = cstate.band_log_amplitude(np.concatenate([s[:, None], path], axis=1))  # (d, S + 1, B)
        over = level >= log_threshold
        first = np.argmax(over, axis=1)                               # first day at or past it
        crossed = over.any(axis=1)
        before = np.take_along_axis(level, np.maximum(first - 1, 0)[:, None], axis=1)[:, 0]
        at = np.take_along_axis(level, first[:, None], axis=1)[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            frac = np.where(at > before, (log_threshold - before) / (at - before), 1.0)
        days = np.where(first == 0, 0.0, first - 1 + np.clip(frac, 0.0, 1.0))
        mean = np.einsum("df,fbp->dbp", k, year) / len(season)
        later = len(season) + cstate.passes_to_band_level(path[:, -1], mean, log_threshold)
        out[lo:lo + block] = np.where(crossed, days, later)
    return out
