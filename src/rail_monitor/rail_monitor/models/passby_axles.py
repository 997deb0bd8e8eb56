"""Pass-by of a train as moving point sources, one per axle (ISO 3095:2013's moving train).

Each pass's train is ``vehicles`` identical vehicles of pitch P = L / vehicles, each with k axles:
for even k two bogies, their centres ``bogie_centre_ratio`` x P apart about the vehicle's middle,
with k / 2 axles each spread over twice the semi-wheelbase; for odd k, axles evenly along the
vehicle. Each axle radiates P / k of the train's power per metre W' [W/m] as a point source with
the kernel g(x) of :mod:`rail_monitor.models.passby` (spreading, horizontal directivity, direct
and image paths), x its position along the track past the receiver's perpendicular. So the
train's total power, and its TEL, are the line source's; LpAeq,Tp and LpAFmax see the axles.

* LpAeq,Tp (exact, every axle): the axle at s_a behind the front travels from -s_a to L - s_a
  while the train passes, so the mean kernel is (P / k) (1 / L) sum_a [G(L - s_a) + G(s_a)].
* LpAFmax: the squared pressure sum_a (P / k) g(x_a(t)) sampled at the larger of tau / 8 and
  the time to travel 1/16 of the receiver's distance, then F weighted (IEC 61672-1, tau =
  0.125 s, a = exp(-dt / tau)) from 6 tau before the train's middle passes to one vehicle period
  (at most 16 path distances of travel: past that a vehicle's bogies pass as separate, equal
  events) and 3 tau after it, started in steady state. The vehicles within 8 path distances of
  the receiver over that window are summed axle by axle; the others, where g is smooth on the
  scale of a vehicle, as the line segments they occupy (G differences), so the cost is bounded
  whatever the train's length. Every pass has its own step, window and near vehicles, and its
  axles are summed one at a time in a fixed order: a pass gives the same bits in any batch.

A vehicle given more than MAX_AXLES_PER_VEHICLE axles is laid out with that many, carrying the
same power.

Moving point sources raise LpAFmax over the line source of the same power by about 1-1.5 dB at
7.5 m (each bogie passes as a peak the F weighting partly follows), and leave TEL unchanged.

References
----------
.. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by railbound
   vehicles*, International Organization for Standardization, Geneva, 2013 (3.6 LpAeq,Tp, 3.8 TEL).
.. [2] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, 5.8.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.axle_layout import AxleLayout
from rail_monitor.models.engine import check_engine
from rail_monitor.models.passby_kernel import (
    kernel_antiderivative,
)

FloatArray = NDArray[np.float64]

PASS_CHUNK = 4096           # passes per block of the exact window kernel
# Points (times x path distances, over a block's passes) per block of the numpy time history, and
# per step of its axle columns: each temporary (<= 128 kB) stays in a core's L2 cache (16,000 and
# 64,000 were 1.2x slower on the sample's batches of 200 passes, 200,000 4x). The blocks change no
# bit: the terms are elementwise and a pass's axles are summed one at a time in a fixed order.
HISTORY_ELEMENTS = 32_000


def _axle_offsets(layout: AxleLayout, first: NDArray[np.int64], count: NDArray[np.int64], width: int):
    """The offsets behind the front [m] of the axles of vehicles first ... first + count - 1, in a
    fixed order (vehicle, then axle), as blocks (passes, <= width), NaN where a pass has no axle."""
    k = layout.offsets_m.shape[1]
    total = int(count.max(initial=0)) * k
    for lo in range(0, total, width):
        column = np.arange(lo, min(lo + width, total))
        j, i = column // k, column % k
        offset = (first[:, None] + j[None, :]) * layout.pitch_m[:, None] + layout.offsets_m[:, i]
        offset[j[None, :] >= count[:, None]] = np.nan
        yield offset


def _sum_over_axles(layout: AxleLayout, first: NDArray[np.int64], count: NDArray[np.int64], term,
                    width: int) -> FloatArray:
    """sum over vehicles first ... first + count - 1 and their axles of term(offsets behind the
    front [m], (passes, w)) -> (passes, w, ...), the term evaluated on up to width axles at once
    and summed one axle at a time in a fixed order, so that a pass's sum is the same bits whatever
    other passes share the call (the terms are elementwise)."""
    total = None
    for offset in _axle_offsets(layout, first, count, width):
        on = np.isfinite(offset)
        value = term(np.where(on, offset, 0.0))
        if not on.all():
            value = np.where(on.reshape(on.shape + (1,) * (value.ndim - 2)), value, 0.0)
        for axle in range(value.shape[1]):
            if total is None:
                total = value[:, axle].copy()
            else:
                total += value[:, axle]
    return np.zeros(len(count)) if total is None else total


def window_kernel(layout: AxleLayout, length_m: ArrayLike, d: float, r: float, engine: str = "numpy") -> FloatArray:
    """Mean over the pass-by time of the kernel of every axle, exactly.

    Parameters
    ----------
    layout : AxleLayout
        The trains' axles [m].
    length_m : array_like
        Train length per pass [m].
    d : float
        Horizontal distance [m].
    r : float
        Path distance R [m].
    engine : str
        'numpy' or 'numba' [-].

    Returns
    -------
    ndarray
        Window mean [1/m] per pass.

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.6 and 3.8 (the pass-by time, LpAeq,Tp and TEL).
    """
    return window_kernels(layout, length_m, d, [r], engine)[0]


def window_kernels(layout: AxleLayout, length_m: ArrayLike, d: float, radii: Sequence[float],
                   engine: str = "numpy") -> FloatArray:
    """:func:`window_kernel` for each path distance, once per distinct train geometry.

    A pass's kernel depends on its train's geometry only, so it is computed once per distinct train
    (a history holds few: consists of whole vehicles) and copied to the passes alike.

    Parameters
    ----------
    layout, length_m, d : AxleLayout, array_like, float
        As for :func:`window_kernel`: the axles, train lengths and horizontal distance [m].
    radii : sequence of float
        Path distances R [m].
    engine : str
        'numpy' or 'numba' [-].

    Returns
    -------
    ndarray
        Window means [1/m], radii x passes.

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.6 and 3.8.
    """
    length = np.atleast_1d(np.asarray(length_m, float))
    check_engine(engine)
    if len(length) > 1:
        first, inverse = distinct_trains(layout, length)
        if len(first) < len(length):
            return _window_kernels(layout.take(first), length[first], d, radii, engine)[:, inverse]
    return _window_kernels(layout, length, d, radii, engine)


def distinct_trains(layout: AxleLayout, length: FloatArray) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The first pass of each distinct train geometry, and each pass's index among them.

    Trains are alike when their length, vehicles, pitch and axle offsets are equal bit for bit.

    Parameters
    ----------
    layout : AxleLayout
        The trains' vehicles and axle offsets [m].
    length : ndarray
        Train length per pass [m].

    Returns
    -------
    tuple of ndarray
        The first pass of each distinct geometry [-] and each pass's geometry [-].

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, clause 3 (the pass-by time depends on the train's length).
    """
    vehicles = np.asarray(layout.vehicles, np.int64).view(np.float64)  # its bits, as a float column of the key
    rows = np.column_stack([length, vehicles, layout.pitch_m, layout.offsets_m])
    keys = np.ascontiguousarray(rows).view(np.dtype((np.void, rows.dtype.itemsize * rows.shape[1])))[:, 0]
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    return first, inverse.ravel()


def _window_kernels(layout: AxleLayout, length: FloatArray, d: float, radii: Sequence[float],
                    engine: str) -> FloatArray:
    if engine == "numba":
        from rail_monitor.models.passby_axles_jit import window_sums

        return layout.length_per_axle_m * window_sums(layout, length, d, list(radii)) / length
    out = np.empty((len(radii), len(length)))
    order = np.argsort(layout.vehicles, kind="stable")   # blocks alike in vehicles: few idle columns
    for lo in range(0, len(length), PASS_CHUNK):
        part = order[lo:lo + PASS_CHUNK]
        sub = layout.take(part)
        ell = length[part, None]
        for k, r in enumerate(radii):
            both = _sum_over_axles(sub, np.zeros(len(part), np.int64), sub.vehicles,
                                   lambda s, ell=ell, r=r: kernel_antiderivative(ell - s, d, r)
                                   + kernel_antiderivative(s, d, r), max(1, HISTORY_ELEMENTS // len(part)))
            out[k, part] = sub.length_per_axle_m * both / length[part]
    return out


