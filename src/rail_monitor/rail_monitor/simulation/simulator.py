"""Synthetic but realistic traffic at a curve: seeded, reproducible, vectorised.

Train arrivals are a Poisson process whose rate follows an hourly timetable profile; each
train draws a vehicle class by traffic share, a consist length, a pass speed from the class's
truncated normal distribution, a leading-axle angle of attack from the curve geometry, and a
friction state from a weather process, a leaf-fall season and a friction-modifier schedule.

Angle of attack: a bogie with semi-wheelbase a curving under flange contact yaws its leading
axle by about a/R from the radial position (geometric curving; see e.g. D. J. Thompson,
Railway Noise and Vibration, Elsevier 2009, ch. 9 on curve squeal, and Rudd, JSV 46 (1976)).
We draw psi = f a/R x lognormal scatter, with f the class-independent curving factor.

Wet spells are a two-state Markov chain sampled per hour: P(dry->wet) and P(wet->dry) are set
by the long-run wet fraction and the mean wet-spell length.
"""

from __future__ import annotations

from datetime import UTC, datetime

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.friction import ACTION_START, ACTION_STOP, ApplicatorEvent
from rail_monitor.core.passes import (
    FRICTION_CONTAMINATED,
    FRICTION_DRY,
    FRICTION_MODIFIER,
    FRICTION_WET,
    PassTable,
)
from rail_monitor.core.simulator_params import SimulatorConfig
from rail_monitor.core.site import Site
from rail_monitor.core.timeutil import NS_PER_DAY, NS_PER_HOUR, NS_PER_S

_HOURS_PER_DAY = 24


def _arrivals(rng: np.random.Generator, cfg: SimulatorConfig) -> np.ndarray:
    """Pass times [ns], sorted: Poisson counts per hour from the profile, uniform within the hour."""
    n_hours = int(np.ceil(cfg.days * _HOURS_PER_DAY))
    hour_of_day = (np.arange(n_hours) + (cfg.start_ns // NS_PER_HOUR)) % _HOURS_PER_DAY
    counts = rng.poisson(cfg.trains_per_hour[hour_of_day])
    hour_start = cfg.start_ns + np.repeat(np.arange(n_hours, dtype=np.int64), counts) * NS_PER_HOUR
    offsets = (rng.random(counts.sum()) * NS_PER_HOUR).astype(np.int64)
    t = np.sort(hour_start + offsets)
    return t[t < cfg.start_ns + int(cfg.days * NS_PER_DAY)]


def _wet_hours(rng: np.random.Generator, cfg: SimulatorConfig, n_hours: int) -> np.ndarray:
    """Two-state Markov chain per hour: True where the rail is wet."""
    p_wet_dry = 1.0 / cfg.wet_spell_mean_h
    p_dry_wet = min(1.0, p_wet_dry * cfg.wet_fraction / max(1e-12, 1.0 - cfg.wet_fraction))
    u = rng.random(n_hours)
    wet = np.empty(n_hours, dtype=bool)
    state = bool(rng.random() < cfg.wet_fraction)
    for i in range(n_hours):  # sequential by nature; n_hours is small (24 per day)
        state = (u[i] >= p_wet_dry) if state else (u[i] < p_dry_wet)
        wet[i] = state
    return wet


def simulate(site: Site, cfg: SimulatorConfig) -> PassTable:
    """Generate the train passes of cfg.days at the site (deterministic for a given seed)."""
    rng = np.random.Generator(np.random.PCG64(cfg.seed))
    t = _arrivals(rng, cfg)
    n = len(t)
    names = list(site.vehicles)
    classes = [site.vehicles[k] for k in names]
    share = np.array([c.traffic_share for c in classes], dtype=np.float64)
    if share.sum() <= 0.0:
        raise ConfigError("the vehicle classes' traffic_share values sum to zero")
    pick = rng.choice(len(classes), size=n, p=share / share.sum())

    def per_class(attr: str) -> np.ndarray:
        return np.array([getattr(c, attr) for c in classes])[pick]

    vehicles = rng.integers(per_class("vehicles_min"), per_class("vehicles_max") + 1)
    mean, sd = per_class("speed_mean_mps"), per_class("speed_sd_mps")
    lo, hi = per_class("speed_min_mps"), per_class("speed_max_mps")
    sd_safe = np.where(sd > 0.0, sd, 1.0)
    from scipy import stats  # lazy: scipy.stats costs 0.3 s to import

    z = stats.truncnorm.rvs((lo - mean) / sd_safe, (hi - mean) / sd_safe, size=n, random_state=rng)
    speed = np.where(sd > 0.0, mean + sd_safe * z, np.clip(mean, lo, hi))

    aoa_mean = cfg.curving_factor * per_class("bogie_semi_wheelbase_m") / site.curve_radius_m
    aoa = aoa_mean * rng.lognormal(-0.5 * cfg.aoa_scatter**2, cfg.aoa_scatter, size=n)
    load = per_class("wheel_load_n") * (1.0 + cfg.wheel_load_sd_fraction * rng.standard_normal(n))

    # Friction: contaminated (leaf season) before wet before friction modifier before dry.
    hour = (t - cfg.start_ns) // NS_PER_HOUR
    wet = _wet_hours(rng, cfg, int(hour.max(initial=0)) + 1)[hour]
    day_of_year = np.array([datetime.fromtimestamp(s // NS_PER_S, UTC).timetuple().tm_yday for s in t],
                           dtype=np.int64)
    s0, s1 = cfg.leaf_season_start_doy, cfg.leaf_season_end_doy
    in_season = (day_of_year >= s0) & (day_of_year <= s1) if s0 <= s1 else (day_of_year >= s0) | (day_of_year <= s1)
    contaminated = in_season & (rng.random(n) < cfg.contaminated_probability)
    day = (t - cfg.start_ns) / NS_PER_DAY
    fm_on = (cfg.friction_modifier_start_day >= 0.0) & (day >= cfg.friction_modifier_start_day) & (
        day < cfg.friction_modifier_end_day)
    fm = fm_on & (rng.random(n) < cfg.friction_modifier_coverage)
    friction = np.select([contaminated, wet, fm], [FRICTION_CONTAMINATED, FRICTION_WET, FRICTION_MODIFIER],
                         FRICTION_DRY)

    cls_names = np.array(names, dtype=object)[pick]
    return PassTable(
        stamp_ns=t,
        train_id=np.array([f"{c.upper()}-{i:06d}" for i, c in enumerate(cls_names, start=1)], dtype=object),
        vehicle_class=cls_names,
        vehicle_count=vehicles,
        axle_count=vehicles * per_class("axles_per_vehicle"),
        speed_mps=np.round(speed, 3),               # a detector reports mm/s resolution
        angle_of_attack_rad=np.round(aoa, 6),       # and micro-radians
        wheel_load_n=np.round(load, 0),
        friction_state=friction,
        train_length_m=np.round(vehicles * per_class("vehicle_length_m"), 2),
    )


SIMULATED_PRODUCT = "top-of-rail friction modifier (simulated)"


def applicator_events(cfg: SimulatorConfig) -> list[ApplicatorEvent]:
    """The friction-modifier applicator's start and stop inside the history, from its service days
    (``simulator.friction_modifier_start_day`` and ``_end_day``): the site events a history of that
    traffic carries."""
    start, end = cfg.friction_modifier_start_day, cfg.friction_modifier_end_day
    if not 0.0 <= start < min(end, cfg.days):
        return []
    out = [ApplicatorEvent(cfg.start_ns + round(start * NS_PER_DAY), ACTION_START, SIMULATED_PRODUCT)]
    if end < cfg.days:
        out.append(ApplicatorEvent(cfg.start_ns + round(end * NS_PER_DAY), ACTION_STOP, SIMULATED_PRODUCT))
    return out
