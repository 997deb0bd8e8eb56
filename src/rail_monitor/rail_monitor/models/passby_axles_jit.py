"""The per-axle pass-by's F-weighted peak compiled by numba: the arithmetic of
models.passby_axles (its numpy engine), fused into one loop per pass so no time history is held.

Every operation is that of the numpy engine in the same order (each axle's term over one common
denominator, models.passby_axles_peak.near_axle_terms; the sum over axles vehicle by vehicle, then the
far line segments, then the paths, then IEC 61672-1's exponential average), without
fast-math, so the two agree to the bit but for the arctangent, which numba takes from the C
library and numpy from its own SIMD routines (they differ in the last bit for some arguments).
Compiled once per machine (numba's cache, next to this file or in NUMBA_CACHE_DIR) and releasing
the interpreter lock, so batch mode's threads use every core.

References
----------
.. [1] S. K. Lam, A. Pitrou and S. Seibert, "Numba: a LLVM-based Python JIT compiler", *Proc. 2nd
   Workshop on the LLVM Compiler Infrastructure in HPC*, ACM, 2015, doi:10.1145/2833157.2833162.
"""

from __future__ import annotations

from collections.abc import Sequence

import numba
import numpy as np
from numpy.typing import NDArray

from rail_monitor.models.axle_layout import AxleLayout
from rail_monitor.models.passby_kernel import BROADSIDE, OMNI, same_path

FloatArray = NDArray[np.float64]
_FOUR_PI = 4.0 * np.pi


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _antiderivative(x: float, d: float, r: float, close: bool, at_d: float) -> float:
    """models.passby_kernel._antiderivative_with at one x (at_d = atan(x / d) / d, shared by the radii)."""
    at_r = np.arctan(x / r) / r
    broad = 0.5 * x / (d * d + x * x) + 0.5 * at_d if close else d * d * (at_d - at_r) / (r * r - d * d)
    return (OMNI * at_r + BROADSIDE * broad) / _FOUR_PI


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _peaks(length, speed, dt, decay, before, samples, lo, hi, vehicles, pitch, offsets, weight, d, radii, close,
           use, count, c, out):  # pragma: no cover  (compiled; its twin is the numpy engine)
    n_r, n_m = len(radii), out.shape[0]
    r2 = radii * radii
    broad = BROADSIDE * d * d
    longest = samples.max() if len(samples) else 0
    front = np.empty(longest)
    x = np.empty((n_r, longest))
    for i in range(len(length)):
        n_t = samples[i]
        for n in range(n_t):
            front[n] = 0.5 * length[i] + speed[i] * ((n - before[i]) * dt[i])
        x[:, :n_t] = 0.0
        # Axle by axle, vehicle by vehicle: each time sample sums its axles in the numpy engine's
        # order; the loops over samples are the vectorisable ones.
        for j in range(lo[i], hi[i] + 1):
            for q in range(offsets.shape[1]):
                off = offsets[i, q]
                if np.isnan(off):
                    continue
                s = j * pitch[i] + off
                for a in range(0, n_r, 2):  # the path distances in pairs (near_axle_terms)
                    ra = r2[a]
                    if a + 1 == n_r:
                        for n in range(n_t):
                            xa = front[n] - s
                            x2 = xa * xa
                            d0 = x2 + d * d
                            x[a, n] += (broad + OMNI * d0) / (d0 * (x2 + ra))
                        continue
                    rb = r2[a + 1]
                    for n in range(n_t):
                        xa = front[n] - s
                        x2 = xa * xa
                        d0, da, db = x2 + d * d, x2 + ra, x2 + rb
                        q = (broad + OMNI * d0) / (d0 * da * db)
                        x[a, n] += q * db
                        x[a + 1, n] += q * da
        for k in range(n_r):
            for n in range(n_t):
                x[k, n] = weight[i] * x[k, n]
        if lo[i] > 0 or hi[i] < vehicles[i] - 1:
            for n in range(n_t):
                f = front[n]
                head = f - lo[i] * pitch[i]
                tail = f - (hi[i] + 1) * pitch[i]
                rear = f - length[i]
                f_d, h_d = np.arctan(f / d) / d, np.arctan(head / d) / d
                t_d, r_d = np.arctan(tail / d) / d, np.arctan(rear / d) / d
                for k in range(n_r):
                    r, cl = radii[k], close[k]
                    x[k, n] += (_antiderivative(f, d, r, cl, f_d) - _antiderivative(head, d, r, cl, h_d)
                                + _antiderivative(tail, d, r, cl, t_d) - _antiderivative(rear, d, r, cl, r_d))
        a = decay[i]
        b0 = 1.0 - a
        for m in range(n_m):
            peak = -np.inf
            state = 0.0
            for n in range(n_t):
                total = 0.0
                for p in range(count[m]):
                    total += c[m, p, i] * x[use[m, p], n]
                if n == 0:
                    state = a * total
                y = b0 * total + state
                state = a * y
                peak = max(peak, y)
            out[m, i] = peak


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _window_sums(length, vehicles, pitch, offsets, d, radii, close, out):  # pragma: no cover
    for i in range(len(length)):
        for k in range(len(radii)):
            out[k, i] = 0.0
        for j in range(vehicles[i]):
            for q in range(offsets.shape[1]):
                off = offsets[i, q]
                if np.isnan(off):
                    continue
                s = j * pitch[i] + off
                a = length[i] - s
                a_d, s_d = np.arctan(a / d) / d, np.arctan(s / d) / d
                for k in range(len(radii)):
                    r, cl = radii[k], close[k]
                    out[k, i] += _antiderivative(a, d, r, cl, a_d) + _antiderivative(s, d, r, cl, s_d)


def window_sums(layout: AxleLayout, length: FloatArray, d: float, radii: list[float]) -> FloatArray:
    """models.passby_axles.window_kernel's sum over every axle of G(L - s) + G(s), compiled, per
    path distance (radii x passes)."""
    out = np.empty((len(radii), len(length)))
    _window_sums(length, layout.vehicles, layout.pitch_m, np.ascontiguousarray(layout.offsets_m), float(d),
                 np.asarray(radii, float), np.array([same_path(d, rk) for rk in radii]), out)
    return out


def f_weighted_peaks(length: FloatArray, speed: FloatArray, dt: FloatArray, decay: FloatArray,
                     before: NDArray[np.int64], samples: NDArray[np.int64], lo: NDArray[np.int64],
                     hi: NDArray[np.int64], layout: AxleLayout, weight: FloatArray, d: float, radii: list[float],
                     use: Sequence[Sequence[int]], c: Sequence[Sequence[FloatArray]]) -> FloatArray:
    """models.passby_axles_peak.f_weighted_peaks's numba engine, given its per-pass windows (models x passes)."""
    n = len(length)
    width = max(len(u) for u in use)
    use_a = np.zeros((len(use), width), np.int64)
    c_a = np.zeros((len(use), width, n))
    for m, (ks, cs) in enumerate(zip(use, c, strict=True)):
        use_a[m, :len(ks)] = ks
        for p, ci in enumerate(cs):
            c_a[m, p] = ci
    out = np.empty((len(use), n))
    r = np.asarray(radii, float)
    close = np.array([same_path(d, rk) for rk in radii])
    _peaks(length, speed, dt, decay, before, samples, lo, hi, layout.vehicles, layout.pitch_m,
           np.ascontiguousarray(layout.offsets_m), weight, float(d), r, close, use_a,
           np.array([len(u) for u in use], np.int64), c_a, out)
    return out
