"""The corrugation model's array kernels compiled by numba: a band's r.m.s. from its components,
the passes until it reaches a level, and a history's sums (models.corrugation's numpy functions
of the same names, whose docstrings give the equations).

The same operations in the same order, one band at a time, without fast-math: the results agree
with the numpy engine but for the last bit of exp and log (numba takes them from the C library,
numpy from its own SIMD routines). Compiled once per machine (numba's cache) and releasing the
interpreter lock.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
MAX_NEWTON_STEPS = 200  # as models.corrugation_state._passes_to_level
STEP_TOL, LEFT_TOL = 1e-12, 1e-13  # as models.corrugation_state


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _band_log_amplitude(x, out):  # pragma: no cover  (compiled; its twin is the numpy engine)
    for m in range(x.shape[0]):
        top = x[m, 0]
        for p in range(1, x.shape[1]):
            top = max(top, x[m, p])
        total = 0.0
        for p in range(x.shape[1]):
            total += np.exp(2.0 * (x[m, p] - top))
        out[m] = top + 0.5 * np.log(total)


def band_log_amplitude(log_components: ArrayLike) -> FloatArray:
    """models.corrugation_state.band_log_amplitude, compiled: ln of each band's r.m.s. [ln m]."""
    x = np.asarray(log_components, float)
    flat = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
    out = np.empty(len(flat))
    _band_log_amplitude(flat, out)
    return out.reshape(x.shape[:-1])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _excess(x, g, target, n):  # pragma: no cover
    """(ln(band r.m.s.) - ln(level), its slope, its curvature in n) of one band's components
    after n passes."""
    top = -np.inf
    for p in range(len(x)):
        top = max(top, 2.0 * (x[p] + g[p] * n))
    total = 0.0
    slope = 0.0
    second = 0.0
    for p in range(len(x)):
        w = np.exp(2.0 * (x[p] + g[p] * n) - top)
        total += w
        wg = w * g[p]
        slope += wg
        second += wg * g[p]
    slope = slope / total
    return 0.5 * (top + np.log(total)) - target, slope, 2.0 * (second / total - slope * slope)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _passes_to_level(x, g, target, out):  # pragma: no cover
    for m in range(x.shape[0]):
        xm, gm = x[m], g[m]
        grows = False
        alone = np.inf
        for p in range(len(xm)):
            if gm[p] > 0:
                grows = True
                alone = min(alone, (target[m] - xm[p]) / gm[p])
        # At the level already: f(0) >= 0. Decided without f(0) where its bounds decide it (the band's
        # r.m.s. lies between its largest component and sqrt(P) times that), which gives the same
        # branch as evaluating it: f(0) >= x_max - level exactly, as the largest term is exp(0) = 1.
        top = xm.max()
        if top >= target[m] or (top + 0.5 * np.log(len(xm)) + 1e-9 >= target[m]
                                and _excess(xm, gm, target[m], 0.0)[0] >= 0):
            out[m] = 0.0
            continue
        if not grows:
            out[m] = np.inf
            continue
        n = alone
        for _ in range(MAX_NEWTON_STEPS):
            f, df, d2f = _excess(xm, gm, target[m], n)
            slope = df if df > 0 else np.inf
            step = f / slope if f > 0 else 0.0
            n -= step
            scale = max(n, 1.0)
            if not (step > STEP_TOL * scale and 0.5 * d2f / slope * step * step > LEFT_TOL * scale):
                break
        out[m] = n


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _first_band_to_level(x, g, target, band, passes):  # pragma: no cover
    """Per state, _passes_to_level's argmin over bands without solving the bands that cannot be it.

    A band's root n* is at most where its fastest component alone reaches the level (Newton starts
    there and only steps down), and at least min over growing p of (level - 0.5 ln P - ln Z_p) / g_p
    (the r.m.s. is at most sqrt(P) times its largest component) when no other component is that
    close to the level already. A band whose lower bound exceeds another band's upper bound, or
    the best root found so far, is not solved; the others are solved as _passes_to_level solves
    them, so the chosen band and its passes are the same bits."""
    n_s, n_b, n_p = x.shape
    half_log_p = 0.5 * np.log(n_p)
    lower = np.empty(n_b)
    one = np.empty(1)
    for i in range(n_s):
        upper = np.inf
        for m in range(n_b):
            lo, hi, sure = np.inf, np.inf, True
            for p in range(n_p):
                xp, gp = x[i, m, p], g[i, m, p]
                if not (np.isfinite(xp) and np.isfinite(gp)):
                    sure = False
                elif gp > 0:
                    hi = min(hi, (target[m] - xp) / gp)
                    lo = min(lo, (target[m] - half_log_p - xp) / gp)
                elif xp >= target[m] - half_log_p:
                    lo = 0.0
            lower[m] = max(lo, 0.0) if sure else -np.inf
            if sure:
                upper = min(upper, max(hi, 0.0))
        best, first = np.inf, -1
        for m in range(n_b):
            bound = min(best, upper)
            if lower[m] > bound + 1e-9 * max(bound, 1.0):
                continue
            _passes_to_level(x[i, m:m + 1], g[i, m:m + 1], target[m:m + 1], one)
            v = one[0]
            if v != v:          # NaN: argmin's choice, whatever follows
                best, first = v, m
                break
            if v < best:
                best, first = v, m
        band[i], passes[i] = first, best


def first_band_to_level(log_components: ArrayLike, growth: ArrayLike,
                        log_level: ArrayLike) -> tuple[NDArray[np.int64], FloatArray]:
    """models.corrugation_state.first_band_to_level, compiled, solving only the bands that can be first."""
    x, g = np.broadcast_arrays(np.asarray(log_components, float), np.asarray(growth, float))
    shape, (b, p) = x.shape[:-2], x.shape[-2:]
    band, passes = np.empty(int(np.prod(shape)), np.int64), np.empty(int(np.prod(shape)))
    _first_band_to_level(np.ascontiguousarray(x.reshape(-1, b, p)), np.ascontiguousarray(g.reshape(-1, b, p)),
                         np.ascontiguousarray(np.broadcast_to(np.asarray(log_level, float), (b,))), band, passes)
    return band.reshape(shape), passes.reshape(shape)


def passes_to_band_level(log_components: ArrayLike, growth: ArrayLike, log_level: ArrayLike) -> FloatArray:
    """models.corrugation_state.passes_to_band_level, compiled: passes [-] until each band's r.m.s.
    reaches the level."""
    x, g = np.broadcast_arrays(np.asarray(log_components, float), np.asarray(growth, float))
    shape, p = x.shape[:-1], x.shape[-1]
    target = np.ascontiguousarray(np.broadcast_to(np.asarray(log_level, float), shape).reshape(-1))
    out = np.empty(target.shape)
    _passes_to_level(np.ascontiguousarray(x.reshape(-1, p)), np.ascontiguousarray(g.reshape(-1, p)), target, out)
    return out.reshape(shape)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _history_sums(log_components, total, by_state, growth, friction, steps, summed):  # pragma: no cover
    summed[0] = total
    for m in range(growth.shape[0]):
        f = friction[m] - 1
        for b in range(growth.shape[1]):
            for p in range(growth.shape[2]):
                g = growth[m, b, p]
                steps[m, b, p] = (log_components[b, p] if m == 0 else steps[m - 1, b, p]) + g
                summed[m + 1, b, p] = summed[m, b, p] + g
                by_state[f, b, p] += g


def history_sums(log_components: FloatArray, total: FloatArray, by_state: FloatArray, growth: FloatArray,
                 friction: NDArray[np.int64]) -> tuple[FloatArray, FloatArray]:
    """models.corrugation_state.history_sums, compiled: one pass over the passes for the three sums."""
    growth = np.ascontiguousarray(growth, float)
    steps = np.empty_like(growth)
    summed = np.empty((len(growth) + 1, *growth.shape[1:]))
    _history_sums(log_components, total, by_state, growth, np.asarray(friction, np.int64), steps, summed)
    return steps, summed


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _window_growth(prefix, start, end, axles, growth, top):  # pragma: no cover
    for m in range(growth.shape[0]):
        for b in range(growth.shape[1]):
            most = -np.inf
            for p in range(growth.shape[2]):
                g = (prefix[end[m], b, p] - prefix[start[m], b, p]) / axles[m]
                growth[m, b, p] = g
                most = max(most, g)
            top[m, b] = most


def window_growth(prefix: FloatArray, start: NDArray[np.int64], end: NDArray[np.int64],
                  axles: FloatArray) -> tuple[FloatArray, FloatArray]:
    """models.corrugation_state.window_growth, compiled: no gathered copies of the prefix sum."""
    n, (_, b, p) = len(end), prefix.shape
    growth, top = np.empty((n, b, p)), np.empty((n, b))
    _window_growth(np.ascontiguousarray(prefix), np.asarray(start, np.int64), np.asarray(end, np.int64),
                   np.asarray(axles, float), growth, top)
    return growth, top


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _add_by_day(daily, day, friction, growth, scale):  # pragma: no cover
    for m in range(growth.shape[0]):
        for b in range(growth.shape[1]):
            for p in range(growth.shape[2]):
                daily[day[m], friction[m], b, p] += growth[m, b, p] * scale[m]


def add_by_day(daily: FloatArray, day: NDArray[np.int64], friction: NDArray[np.int64], growth: FloatArray,
               scale: FloatArray) -> None:
    """models.corrugation_state.add_by_day, compiled."""
    _add_by_day(daily, np.asarray(day, np.int64), np.asarray(friction, np.int64),
                np.ascontiguousarray(growth, float), np.asarray(scale, float))


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _table_growth(table, class_idx, friction, regime, j, w, scale, out):  # pragma: no cover
    for m in range(out.shape[0]):
        lo = table[class_idx[m], friction[m], regime[m], j[m]]
        hi = table[class_idx[m], friction[m], regime[m], j[m] + 1]
        for b in range(out.shape[1]):
            for p in range(out.shape[2]):
                out[m, b, p] = ((1.0 - w[m]) * lo[b, p] + w[m] * hi[b, p]) * scale[m]


def table_growth(table: FloatArray, class_idx: NDArray[np.int64], friction: NDArray[np.int64],
                 regime: NDArray[np.int64], j: NDArray[np.int64], w: FloatArray, scale: FloatArray) -> FloatArray:
    """models.corrugation_state.table_growth, compiled: no gathered copies of the table's rows."""
    out = np.empty((len(j), *table.shape[-2:]))
    _table_growth(table, class_idx, friction, regime, j, np.asarray(w, float), np.asarray(scale, float), out)
    return out
