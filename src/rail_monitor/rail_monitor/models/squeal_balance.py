"""The squeal limit cycle past the closed form: the creep curve as a force, and the energy balance of
a cycle over the whole curve (harmonic balance), with how finely it is solved. The closed form and
its regimes are :mod:`rail_monitor.models.squeal`'s (its module docstring gives the equations and
references); this module holds what both it and the time integration (models.squeal_ode) share.

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and acoustic
   phenomena", seminar paper, sections 2.3 and 3 (eqs. 3-7): the creep curve and its energy balance.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def critical_slip_velocity(speed: ArrayLike, load: ArrayLike, k3: ArrayLike) -> FloatArray:
    """The critical slip velocity u_s = zeta_c V0 = W V0 / k3, where the creep curve saturates.

    Parameters
    ----------
    speed : array_like
        Rolling speed V0 [m/s].
    load : array_like
        Normal load W [N].
    k3 : array_like
        Lateral creep stiffness [N].

    Returns
    -------
    ndarray
        u_s [m/s]: the slip velocity past which the contact slides on the curve's falling
        branch.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eq. 4.
    """
    return np.asarray(load, float) * np.asarray(speed, float) / np.asarray(k3, float)


def creep_force(slip_velocity: ArrayLike, speed: ArrayLike, load: ArrayLike,
                k1: ArrayLike, k2: ArrayLike, k3: ArrayLike) -> FloatArray:
    """Lateral friction force mu(xi') W at a slip velocity.

    The UQ paper's piecewise-linear curve, extended as an odd function of the creepage (reverse
    slip saturates at -k1 and falls with the same slope) and floored at mu = 0 (a falling branch
    never turns friction into propulsion), so that it stays physical where the closed form's
    assumptions fail.

    Parameters
    ----------
    slip_velocity : array_like
        Vc + y' [m/s].
    speed : array_like
        Rolling speed V0 [m/s].
    load : array_like
        Normal load W [N].
    k1 : array_like
        Friction peak [-].
    k2 : array_like
        Slope of the sliding branch [-].
    k3 : array_like
        Lateral creep stiffness [N].

    Returns
    -------
    ndarray
        Force [N], of the sign of the slip velocity (the curve is odd), 0 where the falling
        branch would cross mu = 0.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eqs. 3-4.
    """
    u, v0, w = (np.asarray(x, float) for x in (slip_velocity, speed, load))
    xi = u * np.asarray(k3, float) / (v0 * w)
    ax = np.abs(xi)
    mu = np.where(ax <= 1.0, k1 * ax, np.maximum(k1 + k2 * (ax - 1.0), 0.0))
    return np.sign(xi) * mu * w


HARMONIC_POINTS = 256  # midpoints over half a cycle: the kinks of the curve cost O(1/n^2), 2e-5, in the integral


class BalanceResolution(NamedTuple):
    """How finely the harmonic balance is solved: midpoints over half a cycle, points of the log
    grid of A bracketing the balance (1e-3 to 1e3 times Vc + u_s), and halvings of the bracket."""

    points: int = HARMONIC_POINTS
    bracket: int = 49
    halvings: int = 32


FULL_BALANCE = BalanceResolution()
# A calibration's many evaluations: an integral error O(1/64^2) = 2e-4 and a bracket of a factor
# 1.78 halved 16 times (1e-5 of it): about 0.002 dB in a level, at an eighth of the cost.
COARSE_BALANCE = BalanceResolution(64, 25, 16)


_BALANCE_CHUNK = 2048


def _cycle_work(amplitude: FloatArray, speed: FloatArray, crabbing: FloatArray, load: FloatArray,
                damping: FloatArray, k1: FloatArray, k2: FloatArray, k3: FloatArray,
                points: int = HARMONIC_POINTS) -> FloatArray:
    """Work per cycle on the mode over pi A^2 [N s/m] for y' = A cos(theta): the friction's
    (1 / (pi A)) integral of f(Vc + A cos theta) cos theta d theta, plus the damper's c."""
    theta = (np.arange(points) + 0.5) * (np.pi / points)
    cos = np.cos(theta)
    a = amplitude[:, None]
    f = creep_force(crabbing[:, None] + a * cos, speed[:, None], load[:, None], k1[:, None], k2[:, None],
                    k3[:, None])
    return (2.0 / points) * (f * cos).sum(axis=1) / amplitude + damping


def harmonic_balance_amplitude(speed: ArrayLike, crabbing: ArrayLike, load: ArrayLike, damping: ArrayLike,
                               k1: ArrayLike, k2: ArrayLike, k3: ArrayLike,
                               resolution: BalanceResolution = FULL_BALANCE) -> FloatArray:
    """Limit-cycle velocity amplitude by energy balance over the whole creep curve.

    With y' = A cos(theta), the friction force f = mu(xi') W of :func:`creep_force` and the damper
    do no net work over a cycle: (1/pi) integral_0^2pi f(Vc + A cos theta) cos theta d theta
    + c A = 0. The stable limit cycle is the smallest A > 0 at which the work per cycle turns from
    feeding the mode to draining it; found on a log grid of A (1e-3 to 1e3 times Vc + u_s) and
    refined by bisection.

    Parameters
    ----------
    speed, crabbing, load, damping, k1, k2, k3 : array_like
        V0 [m/s], Vc [m/s], W [N], c [N s/m], k1 [-], k2 [-] and k3 [N], as for
        :func:`rail_monitor.models.squeal.limit_cycle_amplitude`.
    resolution : BalanceResolution
        Midpoints, bracket points and halvings of the solution [-].

    Returns
    -------
    ndarray
        A [m/s]: 0 where the mode is not fed at small amplitude (no squeal), NaN where no balance
        exists on the grid.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eqs. 3-7 (eq. 7 is the closed form this extends).
    """
    arrays = np.broadcast_arrays(*(np.asarray(x, float) for x in (speed, crabbing, load, damping, k1, k2, k3)))
    shape = arrays[0].shape
    v0, vc, w, c, k1, k2, k3 = (a.ravel() for a in arrays)
    vc = np.abs(vc)
    if v0.size > _BALANCE_CHUNK:  # bound the (cases, HARMONIC_POINTS) arrays' memory
        parts = [harmonic_balance_amplitude(*(a[i:i + _BALANCE_CHUNK] for a in (v0, vc, w, c, k1, k2, k3)),
                                            resolution=resolution)
                 for i in range(0, v0.size, _BALANCE_CHUNK)]
        return np.concatenate(parts).reshape(shape)
    scale = vc + critical_slip_velocity(v0, w, k3)
    grid = np.geomspace(1e-3, 1e3, resolution.bracket)
    args = (v0, vc, w, c, k1, k2, k3, resolution.points)
    work = np.stack([_cycle_work(g * scale, *args) for g in grid], axis=1)  # (M, grid)
    turns = (work[:, :-1] < 0.0) & (work[:, 1:] >= 0.0)
    found = turns.any(axis=1)
    j = np.argmax(turns, axis=1)
    lo, hi = grid[j] * scale, grid[np.minimum(j + 1, len(grid) - 1)] * scale
    for _ in range(resolution.halvings):  # 49 points: a bracket of a factor 1.33, 32 halvings leave 1e-10 of it
        mid = 0.5 * (lo + hi)
        feeds = _cycle_work(mid, *args) < 0.0
        lo, hi = np.where(feeds, mid, lo), np.where(feeds, hi, mid)
    out = np.where(found, 0.5 * (lo + hi), np.where(work[:, 0] >= 0.0, 0.0, np.nan))
    return out.reshape(shape)
