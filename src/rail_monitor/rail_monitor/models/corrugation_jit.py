"""The corrugation model's per-band reductions compiled by numba: a band's r.m.s. from its
components and the passes until it reaches a level (models.corrugation's numpy functions of the
same names, whose docstrings give the equations).

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
MAX_NEWTON_STEPS = 200  # as models.corrugation._passes_to_level


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
    """models.corrugation.band_log_amplitude, compiled: ln of each band's r.m.s. [ln m]."""
    x = np.asarray(log_components, float)
    flat = np.ascontiguousarray(x.reshape(-1, x.shape[-1]))
    out = np.empty(len(flat))
    _band_log_amplitude(flat, out)
    return out.reshape(x.shape[:-1])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _excess(x, g, target, n):  # pragma: no cover
    """(ln(band r.m.s.) - ln(level), its slope in n) of one band's components after n passes."""
    top = -np.inf
    for p in range(len(x)):
        top = max(top, 2.0 * (x[p] + g[p] * n))
    total = 0.0
    slope = 0.0
    for p in range(len(x)):
        w = np.exp(2.0 * (x[p] + g[p] * n) - top)
        total += w
        slope += w * g[p]
    return 0.5 * (top + np.log(total)) - target, slope / total


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
        if _excess(xm, gm, target[m], 0.0)[0] >= 0:
            out[m] = 0.0
            continue
        if not grows:
            out[m] = np.inf
            continue
        n = alone
        for _ in range(MAX_NEWTON_STEPS):
            f, df = _excess(xm, gm, target[m], n)
            step = f / (df if df > 0 else np.inf) if f > 0 else 0.0
            n -= step
            if not step > 1e-12 * max(n, 1.0):
                break
        out[m] = n


def passes_to_band_level(log_components: ArrayLike, growth: ArrayLike, log_level: ArrayLike) -> FloatArray:
    """models.corrugation.passes_to_band_level, compiled: passes [-] until each band's r.m.s.
    reaches the level."""
    x, g = np.broadcast_arrays(np.asarray(log_components, float), np.asarray(growth, float))
    shape, p = x.shape[:-1], x.shape[-1]
    target = np.ascontiguousarray(np.broadcast_to(np.asarray(log_level, float), shape).reshape(-1))
    out = np.empty(target.shape)
    _passes_to_level(np.ascontiguousarray(x.reshape(-1, p)), np.ascontiguousarray(g.reshape(-1, p)), target, out)
    return out.reshape(shape)
