"""Networks of curves for rail-monitor plan's tests, benchmarks and demos: forecasts with their
truth drawn from them (network_outlooks, true_days); and sites to simulate whole, each a variation
of one site file with its own radius, traffic, wet weather and true K_b (network_sites), with the
true rail's due date and its cycles once its history has run (true_outlook_days)."""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.passes import PassTable, accepted_passes
from rail_monitor.core.site import Site
from rail_monitor.corrugation.surveys import apply_grinding
from rail_monitor.economics.outlook import Option, SiteOutlook
from rail_monitor.economics.programme import Z90, Law
from rail_monitor.simulation.surveys import true_estimator

TRUE_GRINDS = 12    # true cycles drawn per curve: a 5-year horizon grinds a 200-day cycle about 9 times


def network_outlooks(n: int, seed: int, spread: tuple[float, float] = (0.15, 0.4), visit_cost: float = 500.0,
                     late_visit_cost: float = 1500.0, options: bool = False) -> list[SiteOutlook]:
    """n sites due in 20-700 days on cycles of 200-800 days (medians, uniform), each forecast
    log-normal with a ln-spread (standard deviation) uniform in ``spread``; costs as the site file's
    defaults give on 500 m (one pass preventive, three corrective). options: each also offers speed
    control (cycle x1-1.3, 0-100 a year) and a friction modifier (x1.5-3, its ln-spread 1.5 times
    grinding's, 100-600 a year)."""
    rng = np.random.default_rng(seed)
    z = Z90 * np.array([-1.0, 0.0, 1.0])
    out = []
    for i in range(n):
        due, cycle, sd = rng.uniform(20, 700), rng.uniform(200, 800), rng.uniform(*spread)
        choices: tuple[Option, ...] = ()
        if options:
            choices = (Option("grind", cycle * np.exp(sd * z)),
                       Option("speed_control", rng.uniform(1.0, 1.3) * cycle * np.exp(sd * z), rng.uniform(0, 100)),
                       Option("friction_modifier", rng.uniform(1.5, 3.0) * cycle * np.exp(1.5 * sd * z),
                              rng.uniform(100, 600)))
        out.append(SiteOutlook(f"site_{i:04d}", 0, due * np.exp(sd * z), cycle * np.exp(sd * z), visit_cost,
                               late_visit_cost, 500.0, choices))
    return out


def true_days(outlooks: list[SiteOutlook], seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Each site's true days to threshold now and per cycle, drawn from its forecasts with one
    normal draw per site (K_b's error: the due date and the cycle move together)."""
    z = np.random.default_rng(seed).standard_normal(len(outlooks))
    laws = [(Law.through(o.due_days), Law.through(o.cycle_days)) for o in outlooks]
    return (np.array([np.exp(d.mu + d.sigma * zi) for (d, _), zi in zip(laws, z, strict=True)]),
            np.array([np.exp(c.mu + c.sigma * zi) for (_, c), zi in zip(laws, z, strict=True)]))


@dataclass(frozen=True)
class NetworkSite:
    """One curve of a simulated network: the edits of the base site file (NAME=VALUE) that make it,
    and its true rail's K_b over the configured one: common to every friction state, and per state
    (that factor times each state's own, FRICTION_* order)."""

    site_id: str
    changes: list[str]
    k_b_factor: float
    k_b_factors: tuple[float, ...]


def network_sites(n: int, seed: int, trains_per_hour: Sequence[float], ratio_sd: float = 0.0) -> list[NetworkSite]:
    """n curves: radius log-uniform in 150-1,200 m, the base timetable scaled by 0.5-2, a wet
    fraction of 0.05-0.35, and a true K_b off the configured one by a log-normal factor (ln-sd 0.5,
    kept within 0.3-3), each friction state's further by its own (ln-sd ratio_sd: the K_b prior's
    kb_prior_ratio_sd draws truths as the forecast assumes them): what the site's surveys must find."""
    rng = np.random.default_rng(seed)
    ratios = np.exp(ratio_sd * np.random.default_rng([seed, 1]).standard_normal((n, 4)))
    out = []
    for i in range(n):
        radius = float(np.exp(rng.uniform(np.log(150.0), np.log(1200.0))))
        profile = np.round(np.asarray(trains_per_hour, float) * rng.uniform(0.5, 2.0), 2)
        wet, factor = rng.uniform(0.05, 0.35), float(np.clip(np.exp(rng.normal(0.0, 0.5)), 0.3, 3.0))
        site_id = f"curve_{i:03d}"
        out.append(NetworkSite(site_id, [f"site_id={site_id}", f"curve_radius_m={radius:.0f}",
                                         f"simulator.trains_per_hour=[{', '.join(f'{x:g}' for x in profile)}]",
                                         f"simulator.wet_fraction={wet:.3f}", f"simulator.seed={seed * 1000 + i}"],
                               round(factor, 3), tuple(np.round(factor * ratios[i], 4).tolist())))
    return out


def true_outlook_days(site: Site, values: Mapping[str, Any], passes: PassTable, k_b_factor: float | Sequence[float],
                      grinds: int = TRUE_GRINDS, seed: int = 0) -> tuple[float, np.ndarray]:
    """The true rail's days to its threshold after the passes, and its cycle after each of the next
    ``grinds`` grinds, at the recent traffic (CorrugationEstimator.forecast of the true K_b: what a
    site's forecast estimates). Each grind leaves its own roughness, each band's level drawn about
    the configured post-grinding one with the site's post_grinding_uncertainty_db: the spread the
    forecast assumes, so a rail ground exactly to the mean (never the case) does not flatter it."""
    truth = true_estimator(site, values, k_b_factor)
    truth.advance(accepted_passes(passes, site))
    due = truth.forecast().days_to_threshold
    rng = np.random.Generator(np.random.PCG64(seed))
    worn, cycles = copy.deepcopy(truth), np.empty(grinds)
    for i in range(grinds):
        ground = copy.deepcopy(worn)
        rms = ground.post_grinding * np.exp(np.sqrt(ground.post_grinding_var) * rng.standard_normal(len(ground.bands)))
        apply_grinding(ground, ground.newest_ns, ground.bands, rms)
        cycles[i] = ground.forecast().days_to_threshold
    return float(due), cycles
