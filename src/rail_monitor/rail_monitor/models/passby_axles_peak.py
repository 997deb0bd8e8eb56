"""The peak of the F-time-weighted pass-by of a train as moving point sources, one per axle (no
rclpy): each axle's squared-pressure kernel per path distance, the time history of the near axles
summed (the far vehicles as the line segments they make) and IEC 61672-1's exponential average,
for several sets of paths on the same trains at once (ISO 3095:2013, 3.7: LpAFmax). The axles and
the window means are :mod:`rail_monitor.models.passby_axles`'s; the compiled twin is
:mod:`rail_monitor.models.passby_axles_jit`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.axle_layout import AxleLayout
from rail_monitor.models.engine import check_engine
from rail_monitor.models.passby_axles import HISTORY_ELEMENTS
from rail_monitor.models.passby_kernel import (
    BROADSIDE,
    F_TIME_CONSTANT_S,
    OMNI,
    Paths,
    exponential_average,
    kernel_antiderivative,
)

FloatArray = NDArray[np.float64]


NEAR_PATH_DISTANCES = 8.0   # vehicles this many path distances from the receiver are summed axle by axle


STEPS_PER_TAU = 8           # time steps per F time constant, at least


SAMPLES_PER_DISTANCE = 16   # time steps per horizontal distance travelled, at least


def f_weighted_peak(paths: Paths, layout: AxleLayout, length_m: ArrayLike, speed_mps: ArrayLike,
                    d: float, engine: str = "numpy", window_r: float | None = None) -> FloatArray:
    """Peak of the F-time-weighted squared pressure of the axles along the paths (c, R).

    c is the A-weighted power per metre of a path (per pass), R its perpendicular distance: the
    direct and image paths of each source line (module docstring).

    Parameters
    ----------
    paths : Paths
        (c [W/m-like, any unit], R [m]) per path.
    layout : AxleLayout
        The trains' axles [m].
    length_m, speed_mps : array_like
        Train length [m] and speed [m/s] per pass.
    d : float
        Horizontal distance [m].
    engine : str
        'numpy' or 'numba' [-].
    window_r : float, optional
        The path distance that sets each pass's window [m] (default the largest of the paths').

    Returns
    -------
    ndarray
        Peak squared pressure per pass [the paths' unit over m], every axle's time history summed.

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, 5.8.
    """
    return f_weighted_peaks([paths], layout, length_m, speed_mps, d, engine, window_r)[0]


def f_weighted_peaks(paths_of: Sequence[Paths], layout: AxleLayout, length_m: ArrayLike, speed_mps: ArrayLike,
                     d: float, engine: str = "numpy", window_r: float | None = None) -> FloatArray:
    """:func:`f_weighted_peak` of several sets of paths on the same trains, sharing time histories.

    The time history of each distinct path distance R is computed once and shared, each set's
    squared pressure being sum_i c_i X_R_i(t). Each pass's time step, window and near vehicles are
    its own (from window_r: a set's peak depends on the sets computed with it only through it), so
    the result is the same bits in a batch as alone. The numba engine (models.passby_axles_jit) is
    equal but for the arctangent's last bit.

    Parameters
    ----------
    paths_of : sequence of Paths
        Each set's (c [W/m-like], R [m]) per path.
    layout, length_m, speed_mps, d, engine, window_r : as for f_weighted_peak
        The axles [m], train lengths [m], speeds [m/s], horizontal distance [m], engine [-] and
        the window's path distance [m], as for :func:`f_weighted_peak`.

    Returns
    -------
    ndarray
        Peak squared pressure [the paths' unit over m], sets x passes.

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, 5.8.
    .. [2] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.7.
    """
    length = np.atleast_1d(np.asarray(length_m, float))
    speed = np.atleast_1d(np.asarray(speed_mps, float))
    radii = list(dict.fromkeys(r for paths in paths_of for _, r in paths))
    use = [[radii.index(r) for _, r in paths] for paths in paths_of]
    c = [[np.broadcast_to(np.asarray(ci, float), length.shape) for ci, _ in paths] for paths in paths_of]
    tau, r = F_TIME_CONSTANT_S, max(radii) if window_r is None else window_r
    dt = np.maximum(tau / STEPS_PER_TAU, d / (SAMPLES_PER_DISTANCE * speed))
    before = np.ceil(6.0 * tau / dt).astype(np.int64)
    samples = before + np.ceil((_travel(layout, r) / speed + 3.0 * tau) / dt).astype(np.int64) + 1
    duration = (samples - 1) * dt
    middle = layout.vehicles // 2
    half = np.ceil(_reach(layout, r, speed, duration) / layout.pitch_m).astype(np.int64)
    lo = np.maximum(middle - half, 0)
    hi = np.minimum(middle + half, layout.vehicles - 1)
    decay = np.exp(-dt / tau)
    weight = layout.length_per_axle_m / (4.0 * np.pi)
    if check_engine(engine) == "numba":
        from rail_monitor.models.passby_axles_jit import f_weighted_peaks as compiled

        return compiled(length, speed, dt, decay, before, samples, lo, hi, layout, weight, d, radii, use, c)
    out = np.empty((len(paths_of), len(length)))
    # Most near axles first (_histories): the passes an axle column reaches lead each block.
    order = np.lexsort((samples, -(hi - lo + 1) * layout.axles_per_vehicle))
    for part in _blocks(samples[order] * len(radii), HISTORY_ELEMENTS):
        part = order[part]
        s_part = samples[part]
        x = _histories(radii, layout.take(part), length[part], speed[part], lo[part], hi[part], weight[part],
                       s_part, before[part], dt[part], d)
        own = np.arange(int(s_part.max()))[None, :] < s_part[:, None]
        rep = np.repeat(part, s_part)
        padded = np.zeros((len(use), *own.shape))   # a row's tail is after its window: the average is causal
        for m, (ks, cs) in enumerate(zip(use, c, strict=True)):
            total = cs[0][rep] * x[ks[0]]
            for k, ck in zip(ks[1:], cs[1:], strict=True):
                total = total + ck[rep] * x[k]
            padded[m][own] = total
        y = exponential_average(padded, decay[part])
        out[:, part] = np.where(own, y, -np.inf).max(axis=2)
    return out


def _blocks(size: NDArray[np.int64], limit: int) -> list[slice]:
    """Consecutive runs of items whose sizes sum to at most limit (an item larger alone)."""
    ends = np.cumsum(size)
    out, start = [], 0
    while start < len(size):
        base = ends[start - 1] if start else 0
        stop = max(start + 1, int(np.searchsorted(ends, base + limit, side="right")))
        out.append(slice(start, stop))
        start = stop
    return out


def _travel(layout: AxleLayout, r: float) -> FloatArray:
    """How far each train moves in its window past the middle [m]: one vehicle period, or for a
    vehicle longer than the near zone, the near zone (its bogies pass as separate, equal events)."""
    return np.minimum(layout.pitch_m, 2.0 * NEAR_PATH_DISTANCES * r)


def _reach(layout: AxleLayout, r: float, speed: FloatArray, duration: FloatArray) -> FloatArray:
    """How far from the receiver a vehicle is summed axle by axle [m]: the near zone, the window's travel, a pitch."""
    return NEAR_PATH_DISTANCES * r + speed * duration + layout.pitch_m


def near_axle_terms(x2: FloatArray, d: float, r2: Sequence[float], broad: float) -> list[FloatArray]:
    """An axle's squared-pressure kernel per path distance, directivity / (x^2 + R_k^2).

    directivity = broad / (x^2 + d^2) + omni. The path distances come in pairs, as the callers give
    them (a source line's direct and image paths; an odd last one alone), each pair over one common
    denominator: with D = x^2 + d^2 and D_a, D_b its pair's, q = (broad + omni D) / (D D_a D_b), the
    terms are q D_b and q D_a. One division per pair instead of three, the same numbers to a few
    ulps. A term depends on its own pair only, so a set of whole source lines gives the same bits
    alone as with others. models.passby_axles_jit does these operations in this order.

    Parameters
    ----------
    x2 : ndarray
        Squared distance along the track to the axle [m2] (any shape).
    d : float
        Horizontal distance [m].
    r2 : sequence of float
        Squared path distances R_k^2 [m2].
    broad : float
        The directivity's broadside weight times d^2 [m2].

    Returns
    -------
    list of ndarray
        One kernel [1/m2] per path distance.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eq. 2.3.15 (the directivity) and
       section 2.5 (spherical spreading).
    """
    d0 = x2 + d * d
    num = OMNI * d0
    num += broad
    out = []
    for a in range(0, len(r2), 2):   # in place where a temporary is not needed again: the same operations
        da = x2 + r2[a]
        den = d0 * da
        if a + 1 == len(r2):
            out.append(np.divide(num, den, out=den))
            continue
        db = x2 + r2[a + 1]
        den *= db
        q = np.divide(num, den, out=den)
        out += [np.multiply(q, db, out=db), np.multiply(q, da, out=da)]
    return out


def _histories(radii: list[float], layout: AxleLayout, length: FloatArray, speed: FloatArray,
               lo: NDArray[np.int64], hi: NDArray[np.int64], weight: FloatArray, samples: NDArray[np.int64],
               before: NDArray[np.int64], dt: FloatArray, d: float) -> FloatArray:
    """X_R(t) per path distance R, (radii, sum of samples): the squared pressure of unit power per
    metre, pass after pass at its own times (n - before) dt [s] after the train's middle passes,
    n < samples; the vehicles lo ... hi axle by axle (weight: P / (k 4 pi) per pass), the rest,
    where a pass has any, as the line segments they occupy. The passes come in decreasing order of
    their near axles (k (hi - lo + 1)).

    Laid out flat, pass after pass (no idle time or axle): the axle column j (vehicle lo + j // k,
    axle j % k) reaches the leading passes, those with more than j near axles."""
    rep = np.repeat(np.arange(len(samples)), samples)
    ends = np.cumsum(samples)
    n = np.arange(int(ends[-1])) - (ends - samples)[rep]
    front = 0.5 * length[rep] + speed[rep] * ((n - before[rep]) * dt[rep])     # [m]
    broad, r2 = BROADSIDE * d * d, [r * r for r in radii]
    k = layout.axles_per_vehicle.astype(np.int64)
    near = (hi - lo + 1) * k
    total = np.zeros((len(radii), len(front)))
    reach = np.searchsorted(-near, -np.arange(int(near[0])), side="right")   # passes each column reaches
    column = 0
    while column < len(reach):
        rows, size = int(reach[column]), int(ends[reach[column] - 1])
        width = max(1, min(len(reach) - column, HISTORY_ELEMENTS // (size * len(radii))))
        cols = np.arange(column, column + width)
        kr = k[:rows, None]
        j, i = cols[None, :] // kr, cols[None, :] % kr
        offset = (lo[:rows, None] + j) * layout.pitch_m[:rows, None] + layout.offsets_m[np.arange(rows)[:, None], i]
        on = cols[None, :] < near[:rows, None]
        x2 = np.subtract(front[None, :size], np.repeat(np.where(on, offset, 0.0).T, samples[:rows], axis=1))
        np.square(x2, out=x2)
        terms = near_axle_terms(x2, d, r2, broad)
        if not on.all():
            idle = np.repeat(~on.T, samples[:rows], axis=1)
            for term in terms:
                term[idle] = 0.0
        if width == 1:
            for kk, term in enumerate(terms):
                total[kk, :size] += term[0]
        else:
            stacked = np.stack(terms, axis=1)   # one addition per column
            for c in range(width):
                total[:, :size] += stacked[c]
        column += width
    total *= weight[rep]
    far = (lo > 0) | (hi < layout.vehicles - 1)
    if not far.any():
        return total
    # The vehicles before lo and after hi, as the line segments they occupy.
    at = far[rep]
    f, which = front[at], rep[at]
    head, tail = f - (lo * layout.pitch_m)[which], f - ((hi + 1) * layout.pitch_m)[which]
    rear = f - length[which]
    g = kernel_antiderivative
    for kk, r in enumerate(radii):
        total[kk, at] += g(f, d, r) - g(head, d, r) + g(tail, d, r) - g(rear, d, r)
    return total
