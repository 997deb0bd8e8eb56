"""Grinding cycles under exponential growth: the worst band's roughness over axle passes, ground
back each time it reaches its threshold, and the grinds made (the shapes of the UQ paper's
Figure 2: growth and cumulative grinding cost, current against advised speeds)."""

from __future__ import annotations

import numpy as np


def sawtooth(post_m: float, threshold_m: float, growth: float, axle_passes: np.ndarray) -> tuple[np.ndarray, ...]:
    """Roughness [m] after each of axle_passes [-] and the grinds made by then [-], growing as
    Z = Z_post exp(g n) (UQ paper eq. 1, g the expected log growth per axle pass) from post_m and
    ground back to it on reaching threshold_m (g <= 0: never ground)."""
    n = np.asarray(axle_passes, float)
    if growth <= 0:
        return np.full(n.shape, post_m), np.zeros(n.shape, int)
    cycle = np.log(threshold_m / post_m) / growth          # axle passes from a grind to the threshold
    grinds = np.floor(n / cycle).astype(int)
    return post_m * np.exp(growth * (n - grinds * cycle)), grinds
