"""The axles of a train as point sources for the pass-by (no rclpy): identical vehicles of pitch
P = train length / vehicles, each with its bogies' axles at the same offsets from its front.
Used by the point source per axle (models.passby_axles) and its compiled twin."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

MAX_AXLES_PER_VEHICLE = 16  # a vehicle given more axles is laid out with this many (the same power)


@dataclass(frozen=True)
class AxleLayout:
    """The axles of each pass's train: identical vehicles of pitch P, each with the same axle
    offsets from its front (NaN past the pass's k axles)."""

    vehicles: NDArray[np.int64]   # (passes,) [-]
    pitch_m: FloatArray           # (passes,) P = train length / vehicles [m]
    offsets_m: FloatArray         # (passes, k_max) from the vehicle's front [m]

    @property
    def axles_per_vehicle(self) -> FloatArray:
        return np.sum(np.isfinite(self.offsets_m), axis=1).astype(float)

    def take(self, rows: NDArray[np.int64]) -> AxleLayout:
        """The layout of the passes at rows."""
        return AxleLayout(self.vehicles[rows], self.pitch_m[rows], self.offsets_m[rows])

    @property
    def length_per_axle_m(self) -> FloatArray:
        """P / k: the length of train whose power each axle radiates [m] (passes,)."""
        return self.pitch_m / self.axles_per_vehicle


def axle_layout(length_m: ArrayLike, vehicle_count: ArrayLike, axle_count: ArrayLike, bogie_centre_ratio: ArrayLike,
                semi_wheelbase_m: ArrayLike) -> AxleLayout:
    """The axles of trains as identical vehicles of pitch P = length / vehicles.

    k = axles / vehicles (rounded, at least 1); bogie centres bogie_centre_ratio x P apart; axles of
    a bogie semi_wheelbase_m either side of its centre (k / 2 = 3: one at the centre too). The
    layout is this package's (docs/models.md, the pass-by's sources); the pass it spans is ISO 3095's.

    Parameters
    ----------
    length_m : array_like
        Train length per pass [m].
    vehicle_count : array_like
        Vehicles per pass [-].
    axle_count : array_like
        Axles per pass [-].
    bogie_centre_ratio : array_like
        Distance between a vehicle's bogie centres over its pitch [-].
    semi_wheelbase_m : array_like
        Half a bogie's wheelbase [m].

    Returns
    -------
    AxleLayout
        Vehicles [-], pitch P [m] and each axle's offset from its vehicle's front [m] per pass.

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, clause 3 (the pass from the train's front to its rear).
    """
    length = np.atleast_1d(np.asarray(length_m, float))
    vehicles = np.maximum(np.atleast_1d(np.asarray(vehicle_count, np.int64)), 1)
    k = np.clip(np.rint(np.atleast_1d(np.asarray(axle_count, float)) / vehicles).astype(np.int64), 1,
                MAX_AXLES_PER_VEHICLE)
    pitch = length / vehicles
    ratio = np.broadcast_to(np.asarray(bogie_centre_ratio, float), length.shape)
    semi = np.broadcast_to(np.asarray(semi_wheelbase_m, float), length.shape)
    offsets = np.full((len(length), int(k.max(initial=1))), np.nan)
    for kk in np.unique(k):
        rows = k == kk
        p, half = pitch[rows, None], kk // 2
        if kk % 2:                                            # odd: evenly along the vehicle
            offsets[rows, :kk] = p * (np.arange(kk) + 0.5) / kk
            continue
        spread = np.linspace(-1.0, 1.0, half) if half > 1 else np.zeros(1)
        bogie = 0.5 * p + 0.5 * ratio[rows, None] * p * np.array([-1.0, 1.0])   # bogie centres (rows, 2)
        axles = bogie[:, :, None] + semi[rows, None, None] * spread[None, None, :]
        offsets[rows, :kk] = np.clip(axles.reshape(-1, kk), 0.0, p)
    return AxleLayout(vehicles, pitch, offsets)
