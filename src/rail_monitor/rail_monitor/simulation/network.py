"""A network of sites as a grinding programme sees it (economics.outlook.SiteOutlook), with each
site's truth: for tests and benchmarks of rail-monitor plan, where the forecasts must be known to
be right (the truth is drawn from them)."""

from __future__ import annotations

import numpy as np

from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.economics.programme import Z90, Law

DAY_NS = 86_400 * 10**9


def network_outlooks(n: int, seed: int, spread: tuple[float, float] = (0.15, 0.4), visit_cost: float = 500.0,
                     late_visit_cost: float = 1500.0) -> list[SiteOutlook]:
    """n sites due in 20-700 days on cycles of 200-800 days (medians, uniform), each forecast
    log-normal with a ln-spread (standard deviation) uniform in ``spread``; costs as the site file's
    defaults give on 500 m (one pass preventive, three corrective)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        due, cycle, sd = rng.uniform(20, 700), rng.uniform(200, 800), rng.uniform(*spread)
        q = np.exp(sd * Z90 * np.array([-1.0, 0.0, 1.0]))
        out.append(SiteOutlook(f"site_{i:04d}", 0, due * q, cycle * q, visit_cost, late_visit_cost, 500.0))
    return out


def true_days(outlooks: list[SiteOutlook], seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Each site's true days to threshold now and per cycle, drawn from its forecasts with one
    normal draw per site (K_b's error: the due date and the cycle move together)."""
    z = np.random.default_rng(seed).standard_normal(len(outlooks))
    laws = [(Law.through(o.due_days), Law.through(o.cycle_days)) for o in outlooks]
    return (np.array([np.exp(d.mu + d.sigma * zi) for (d, _), zi in zip(laws, z, strict=True)]),
            np.array([np.exp(c.mu + c.sigma * zi) for (_, c), zi in zip(laws, z, strict=True)]))
