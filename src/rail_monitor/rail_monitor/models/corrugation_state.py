"""The corrugation state's array kernels in numpy (no rclpy): a band's r.m.s. from its components,
the passes until it reaches a level, the growth table's rows and a history's sums; the numpy twin
of :mod:`rail_monitor.models.corrugation_jit` (models.engine.corrugation_kernels chooses). The growth
they sum is :mod:`rail_monitor.models.corrugation`'s (UQ seminar paper, section 2.1, eqs. 1-2).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.corrugation import FloatArray


def band_log_amplitude(log_components: ArrayLike) -> FloatArray:
    """ln of each band's r.m.s. from its components, ln sqrt(sum_p Z_p^2), without overflow.

    Parameters
    ----------
    log_components : array_like
        ln Z_p of the components [ln m], components on the last axis.

    Returns
    -------
    ndarray
        ln of the band's r.m.s. [ln m].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2 (each component grows as Z_0 exp(n g)).
    """
    x = np.asarray(log_components, float)
    top = x.max(axis=-1, keepdims=True)
    return top[..., 0] + 0.5 * np.log(np.sum(np.exp(2.0 * (x - top)), axis=-1))


def band_amplitude(log_components: ArrayLike) -> FloatArray:
    """r.m.s. of each band from the ln amplitudes of its components.

    Parameters
    ----------
    log_components : array_like
        As for :func:`band_log_amplitude`: ln Z_p [ln m], components on the last axis.

    Returns
    -------
    ndarray
        The band's r.m.s. [m].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    return np.exp(band_log_amplitude(log_components))


BAND_BLOCK = 16384  # bands evaluated together: (P, BAND_BLOCK) arrays stay in cache


STEP_TOL = 1e-12  # a band's Newton iteration stops on a step this small relative to its n (or 1 pass)


LEFT_TOL = 1e-13  # ... or when the error its step leaves is estimated this small, relative likewise


def passes_to_band_level(log_components: ArrayLike, growth: ArrayLike, log_level: ArrayLike) -> FloatArray:
    """Passes until a band's r.m.s. reaches a level: sum_p Z_p^2 exp(2 g_p n) = Z_level^2.

    0 where the band is already at or past the level, inf where no component grows. The left
    side's log is convex in n; Newton's method started where the fastest-growing component alone
    reaches the level (at or beyond the root) converges to the root monotonically from above.

    Evaluated component-major ((P, bands) arrays, so the sums over components are row
    additions, not reductions over a short last axis), in blocks of BAND_BLOCK bands that stay in
    cache, and only on the bands not yet converged. Each band stops on its own, so a band's result
    does not depend on which bands it is evaluated with (one state or a whole history, any
    chunking, give the same bits): when its step s is no more than STEP_TOL of its n, or when the
    error Newton's step leaves, about f''/(2 f') s^2 (quadratic convergence; f' is the energy-weighted
    mean of g_p and f'' twice its variance), is no more than LEFT_TOL of its n, which saves the
    last evaluation that only confirms convergence.

    Parameters
    ----------
    log_components : array_like
        ln Z_p [ln m], shape (..., P).
    growth : array_like
        g_p [1/pass], shape (..., P).
    log_level : array_like
        ln Z_level [ln m], shape (...).

    Returns
    -------
    ndarray
        n [passes], shape (...).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2 (Z_n ~ Z_0 exp(n g)).
    """
    x, g = np.broadcast_arrays(np.asarray(log_components, float), np.asarray(growth, float))
    shape = x.shape[:-1]
    p = x.shape[-1]
    xs = np.ascontiguousarray(x.reshape(-1, p).T)  # (P, M)
    gs = np.ascontiguousarray(g.reshape(-1, p).T)
    target = np.ascontiguousarray(np.broadcast_to(np.asarray(log_level, float), shape).reshape(-1))
    n = np.empty(target.shape)
    for lo in range(0, len(target), BAND_BLOCK):
        cols = slice(lo, lo + BAND_BLOCK)
        n[cols] = _passes_to_level(xs[:, cols], gs[:, cols], target[cols])
    return n.reshape(shape)


def first_band_to_level(log_components: ArrayLike, growth: ArrayLike,
                        log_level: ArrayLike) -> tuple[NDArray[np.int64], FloatArray]:
    """The band that reaches its level first, and its passes.

    Per state (...), the argmin over bands (B) of :func:`passes_to_band_level` (the first of equal
    ones) and its value; band -1 (passes inf) where no band ever reaches its level.

    Parameters
    ----------
    log_components : array_like
        ln Z_p [ln m], shape (..., B, P).
    growth : array_like
        g_p [1/pass], shape (..., B, P).
    log_level : array_like
        ln Z_level per band [ln m], shape (B,).

    Returns
    -------
    tuple of ndarray
        The band index [-] and its passes [passes], each of shape (...).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    .. [2] S. L. Grassie, M. J. Saxon and J. D. Smith, "Measurement of longitudinal rail irregularities
       and criteria for acceptable grinding", *Journal of Sound and Vibration* 227(5) (1999) 949-964 (the levels).
    """
    n = passes_to_band_level(log_components, growth, log_level)
    first = np.argmin(n, axis=-1)
    passes = np.take_along_axis(n, first[..., None], axis=-1)[..., 0]
    return np.where(np.isinf(n).all(axis=-1), -1, first), passes


def _excess(x: FloatArray, g: FloatArray, target: FloatArray,
            n: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """ln(band r.m.s.) - ln(level) after n passes, its slope and its curvature in n, for (P, M)
    components."""
    e = 2.0 * (x + g * n)
    top = e.max(axis=0)
    w = np.exp(e - top)
    total = w.sum(axis=0)
    wg = w * g
    slope = wg.sum(axis=0) / total
    return 0.5 * (top + np.log(total)) - target, slope, 2.0 * ((wg * g).sum(axis=0) / total - slope * slope)


def _passes_to_level(xs: FloatArray, gs: FloatArray, target: FloatArray) -> FloatArray:
    """passes_to_band_level of (P, M) components (Newton from the fastest component's n)."""
    grows = (gs > 0).any(axis=0)
    at_level = _excess(xs, gs, target, np.zeros(target.shape))[0] >= 0
    with np.errstate(divide="ignore", invalid="ignore"):
        alone = np.where(gs > 0, (target - xs) / gs, np.inf)
    n = np.where(grows & ~at_level, alone.min(axis=0), 0.0)
    active = np.flatnonzero(grows & ~at_level)
    for _ in range(200):
        if not len(active):
            break
        f, df, d2f = _excess(xs[:, active], gs[:, active], target[active], n[active])
        slope = np.where(df > 0, df, np.inf)
        step = np.where(f > 0, f / slope, 0.0)
        n[active] -= step
        scale = np.maximum(n[active], 1.0)
        active = active[(step > STEP_TOL * scale) & (0.5 * d2f / slope * step * step > LEFT_TOL * scale)]
    return np.where(at_level, 0.0, np.where(grows, n, np.inf))


def table_growth(table: FloatArray, class_idx: NDArray[np.int64], friction: NDArray[np.int64],
                 regime: NDArray[np.int64], j: NDArray[np.int64], w: FloatArray, scale: FloatArray) -> FloatArray:
    """Rows of a growth table at N passes, linear between speed points j and j + 1 with weight w.

    Parameters
    ----------
    table : ndarray
        Log growth per pass [-], shape (C, F, R, V, B, P): class, friction, regime, speed, band,
        component.
    class_idx : ndarray of int
        Each pass's class row [-] (N,).
    friction : ndarray of int
        Each pass's friction state as an index 0-3 [-] (N,).
    regime : ndarray of int
        Each pass's contact regime (core.contact.REGIME_*) [-] (N,).
    j : ndarray of int
        The speed point below each pass's speed [-] (N,).
    w : ndarray
        The weight of point j + 1 [-] (N,).
    scale : ndarray
        Each pass's multiplier, its axles [-] (N,).

    Returns
    -------
    ndarray
        Log growth [-], shape (N, B, P).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    w = w[:, None, None]
    rows = (class_idx, friction, regime)
    return ((1.0 - w) * table[(*rows, j)] + w * table[(*rows, j + 1)]) * scale[:, None, None]


def history_sums(log_components: FloatArray, total: FloatArray, by_state: FloatArray, growth: FloatArray,
                 friction: NDArray[np.int64]) -> tuple[FloatArray, FloatArray]:
    """A history's sums over passes in counting order, each sequential.

    A batch adds as the same passes one by one would, so any chunking gives the same bits.

    Parameters
    ----------
    log_components : ndarray
        ln Z before the first pass [ln m] (B, P).
    total : ndarray
        The log growth summed so far [-] (B, P).
    by_state : ndarray
        The log growth summed per friction state [-] (4, B, P), updated in place.
    growth : ndarray
        The passes' log growth [-] (N, B, P).
    friction : ndarray of int
        Their friction states [-] (N,) (1-4).

    Returns
    -------
    tuple of ndarray
        ln Z after each pass [ln m] (N, B, P), and the log growth summed before each pass and after
        the last [-] (N + 1, B, P).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2 (Z_n = Z_0 exp(sum of ln|1 + K_b H|)).
    """
    steps = np.cumsum(np.concatenate([log_components[None], growth]), axis=0)[1:]
    for f in np.unique(friction).tolist():
        by_state[f - 1] = np.cumsum(np.concatenate([by_state[f - 1][None], growth[friction == f]]), axis=0)[-1]
    return steps, np.cumsum(np.concatenate([total[None], growth]), axis=0)


def window_growth(prefix: FloatArray, start: NDArray[np.int64], end: NDArray[np.int64],
                  axles: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Growth per axle pass over windows of passes, and its largest component per band.

    Parameters
    ----------
    prefix : ndarray
        Prefix sums of the log growth [-] (K, B, P).
    start : ndarray of int
        Each window's first pass [-] (N,).
    end : ndarray of int
        One past each window's last pass [-] (N,).
    axles : ndarray
        Axle passes in each window [-] (N,).

    Returns
    -------
    tuple of ndarray
        Growth per axle pass [1/axle pass] (N, B, P) and its largest component per band (N, B).

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    growth = (prefix[end] - prefix[start]) / axles[:, None, None]
    return growth, growth.max(axis=2)


def add_by_day(daily: FloatArray, day: NDArray[np.int64], friction: NDArray[np.int64], growth: FloatArray,
               scale: FloatArray) -> None:
    """Adds each pass's growth to its day and friction state: daily[day_i, friction_i] += growth_i scale_i.

    Parameters
    ----------
    daily : ndarray
        Log growth per day and friction state [-] (D, 4, B, P), updated in place.
    day : ndarray of int
        Each pass's day [-] (N,).
    friction : ndarray of int
        Each pass's friction state as an index 0-3 [-] (N,).
    growth : ndarray
        Each pass's log growth [-] (N, B, P).
    scale : ndarray
        Each pass's multiplier [-] (N,) (corrugation.season divides by its state's K_b).

    Returns
    -------
    None
        daily is updated in place.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    np.add.at(daily, (day, friction), growth * scale[:, None, None])
