"""Pass-by levels of a train at a wayside receiver: a moving, finite, incoherent line source, or
(models.passby_axles, through PassGeometry.axles) a moving point source per axle.

Propagation (our choice, documented in docs/models.md): the train is a line of length L along the
track centre line, of uniform directional sound power W' per metre (dB re 1 pW/m), at height
h_s above the rail head, moving at speed v. Each element radiates as a point source in free
field over a flat reflecting ground: the direct path and an image in the ground plane (at
ground_depth below the rail head), added in energy with the ground's energy reflection
coefficient Q (1: hard; 0: free field; or per band |Q|^2 of a porous ground's spherical-wave
reflection, models.ground). Spherical spreading uses CNOSSOS-EU's convention
Lp = L_W - 10 lg(4 pi r^2) (Directive 2015/996 Annex II 2.5.6, A_div = 20 lg d + 11; it takes
rho c = 400 rayl). The horizontal directivity is CNOSSOS-EU's for rolling noise,
D(phi) = 0.01 + 0.99 sin^2 phi (Annex II eq. 2.3.15), phi the angle in plan between the track
and the line to the receiver. No air absorption (under 0.1 dB at 7.5 m below 10 kHz, ISO 9613-1).

With d the horizontal distance and R = sqrt(d^2 + dz^2) the perpendicular distance of a path,
an element at x along the track contributes

    g(x) = [0.01 / (R^2 + x^2) + 0.99 d^2 / ((d^2 + x^2)(R^2 + x^2))] / (4 pi)   [1/m^2]

and every metric follows in closed form from its first and second antiderivatives in x:

* LpAeq,Tp: the mean over the pass-by time Tp = L / v (front to rear past the receiver's
  perpendicular), mean kernel [GG(L) - 2 GG(0) + GG(-L)] / L;
* TEL (ISO 3095:2013 transit exposure level): the whole event's exposure over Tp, kernel
  integral of g over all x: [0.01 / R + 0.99 d / (R (d + R))] / 4;
* LpAFmax: the largest time-weighted level with IEC 61672-1's F time constant (0.125 s), from
  the time history G(vt) - G(vt - L) filtered around its peak.

References
----------
.. [1] Commission Directive (EU) 2015/996 of 19 May 2015 establishing common noise assessment methods
   according to Directive 2002/49/EC, *Official Journal of the European Union* L 168, 1.7.2015,
   Annex II sections 2.3 and 2.5.
.. [2] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by railbound
   vehicles*, International Organization for Standardization, Geneva, 2013.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from rail_monitor.models import passby_axles
from rail_monitor.models.axle_layout import AxleLayout
from rail_monitor.models.ground import spherical_reflection
from rail_monitor.models.iec61260 import exact_centre
from rail_monitor.models.levels import a_weighted, level, power
from rail_monitor.models.passby_kernel import (
    FloatArray,
    kernel_total,
    kernel_window_mean,
)
from rail_monitor.models.passby_paths import BandPaths, PassGeometry, a_weighted_paths, band_paths, f_weighted_peaks

# The pass-by metrics as this module computes them (for every report that shows them).
METRIC_DEFINITIONS = {
    "lpaeq_tp_dba": "LpAeq,Tp: A-weighted equivalent level over the pass-by time Tp = L / v, front to rear past "
                    "the receiver's perpendicular (ISO 3095:2013, 3.6) [dB(A) re 20 uPa]",
    "lpafmax_dba": "LpAFmax: highest A-weighted level with the F time weighting, tau = 0.125 s (IEC 61672-1:2013) "
                   "[dB(A) re 20 uPa]",
    "tel_dba": "TEL: transit exposure level, the whole event's A-weighted sound exposure spread over Tp "
               "(ISO 3095:2013, 3.8) [dB(A) re 20 uPa]",
    "pass_by_time_s": "Tp = train length / speed [s]",
}


@dataclass(frozen=True)
class Receiver:
    """Receiver and source geometry [m], heights above the rail head (ISO 3095:2013 position:
    7.5 m from the track centre, 1.2 m above the rail head; CNOSSOS-EU source A, h = 1, 0.5 m
    above the rail head, Directive 2015/996 Annex II 2.3.1)."""

    distance_m: float = 7.5
    height_m: float = 1.2
    source_height_m: float = 0.5
    ground_depth_m: float = 0.0
    ground_reflection: float = 1.0
    ground_flow_resistivity_pa_s_m2: float = 0.0   # > 0: a porous ground (models.ground) instead

    def image_weight(self, band: ArrayLike) -> float | FloatArray:
        """Energy weight of the image path: ground_reflection, or for a porous ground |Q|^2 per
        band (models.ground.spherical_reflection at the band's exact centre)."""
        if self.ground_flow_resistivity_pa_s_m2 <= 0.0:
            return self.ground_reflection
        _, (r2, psi) = self.paths()
        q = spherical_reflection(exact_centre(band), self.ground_flow_resistivity_pa_s_m2, r2, -psi)
        return np.abs(q) ** 2

    def paths(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """(perpendicular distance R [m], elevation angle psi [rad]) of the direct and image paths."""
        d = self.distance_m
        dz_direct = self.height_m - self.source_height_m
        dz_image = self.height_m + self.source_height_m + 2.0 * self.ground_depth_m
        return ((float(np.hypot(d, dz_direct)), float(np.arctan2(dz_direct, d))),
                (float(np.hypot(d, dz_image)), float(np.arctan2(-dz_image, d))))


@dataclass(frozen=True)
class PassBy:
    """Pass-by levels (arrays over passes; bands on the last axis)."""

    lp_db: FloatArray            # LpAeq,Tp per band (unweighted) [dB re 20 uPa]
    lpaeq_tp_dba: FloatArray     # [dB(A)]
    tel_dba: FloatArray          # [dB(A)]
    lpafmax_dba: FloatArray      # [dB(A)]
    pass_by_time_s: FloatArray   # Tp = L / v [s]


def pass_geometry(band: ArrayLike, length_m: ArrayLike, speed_mps: ArrayLike, receiver: Receiver,
                  axles: AxleLayout | None = None, engine: str = "numpy") -> PassGeometry:
    """What pass-by levels need of the passes, bands and receiver, whatever the spectrum.

    A moving point source per axle of the layout (its kernels by engine, models.passby_axles), or
    without one the uniform line source.

    Parameters
    ----------
    band : array_like
        IEC 61260-1 band numbers [-].
    length_m : array_like
        Train length per pass [m].
    speed_mps : array_like
        Speed per pass [m/s].
    receiver : Receiver
        Receiver and source geometry [m].
    axles : AxleLayout, optional
        The trains' axles (None: a line source) [m].
    engine : str
        'numpy' or 'numba' [-].

    Returns
    -------
    PassGeometry
        Lengths [m], speeds [m/s], distances [m] and the kernels' window means [1/m], shared by every
        spectrum radiated on these passes.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, sections 2.3 and 2.5.
    .. [2] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*.
    """
    length = np.atleast_1d(np.asarray(length_m, float))
    d = receiver.distance_m
    (r1, _), (r2, _) = receiver.paths()
    if axles is None:
        k1, k2 = kernel_window_mean(length, d, r1), kernel_window_mean(length, d, r2)
    else:
        k1, k2 = passby_axles.window_kernels(axles, length, d, [r1, r2], engine)
    return PassGeometry(length, np.atleast_1d(np.asarray(speed_mps, float)), d, r1, r2, k1[:, None], k2[:, None],
                        kernel_total(d, r1), kernel_total(d, r2), power(a_weighted(0.0, band)),
                        receiver.image_weight(band), axles)


def pass_by(lw_per_metre_db: ArrayLike, band: ArrayLike, length_m: ArrayLike, speed_mps: ArrayLike,
            receiver: Receiver, direct_correction_db: ArrayLike = 0.0, time_weighted: bool = True,
            geometry: PassGeometry | None = None,
            elevated: tuple[ArrayLike, PassGeometry] | None = None, engine: str = "numpy") -> PassBy:
    """Pass-by levels of trains from their band sound power per metre.

    direct_correction_db is added to the direct path only (CNOSSOS-EU's vertical directivity of
    source A). time_weighted computes LpAFmax, the costly part (NaN without it; see
    :func:`f_weighted_peaks` for several spectra on the same trains at once). elevated is a second
    source line of the same trains at another height (CNOSSOS-EU's source B, 4 m), without
    directivity correction; its paths join the time history, so LpAFmax is that of both lines
    together.

    Parameters
    ----------
    lw_per_metre_db : array_like
        Sound power per metre [dB re 1 pW/m], passes x bands.
    band : array_like
        IEC 61260-1 band numbers [-].
    length_m, speed_mps : array_like
        Per pass: train length [m] and speed [m/s].
    receiver : Receiver
        Receiver and source geometry [m].
    direct_correction_db : array_like
        Per band, added to the direct path [dB].
    time_weighted : bool
        Whether LpAFmax is computed [-].
    geometry : PassGeometry, optional
        :func:`pass_geometry` of the same bands, passes and receiver, when at hand [-].
    elevated : (array_like, PassGeometry), optional
        The elevated line's power per metre [dB re 1 pW/m] and its geometry.
    engine : str
        Of the per-axle time history, 'numpy' or 'numba' [-].

    Returns
    -------
    PassBy
        LpAeq,Tp per band [dB re 20 uPa], LpAeq,Tp, TEL and LpAFmax [dB(A)] and Tp [s] per pass.

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, sections 2.3 and 2.5.
    .. [2] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.6-3.9.
    """
    g = geometry or pass_geometry(band, length_m, speed_mps, receiver)
    paths = band_paths(lw_per_metre_db, g, direct_correction_db, elevated)
    fmax = level(f_weighted_peaks(g, [a_weighted_paths(g, paths)], engine)[0]) if time_weighted else None
    return pass_by_levels(g, paths, fmax)


def pass_by_levels(g: PassGeometry, paths: BandPaths, lpafmax_dba: FloatArray | None = None) -> PassBy:
    """:func:`pass_by` of the band paths on their geometry, given LpAFmax.

    The A-weighted totals are summed in energy, without a round trip through decibels.

    Parameters
    ----------
    g : PassGeometry
        The passes' geometry [-].
    paths : BandPaths
        :func:`band_paths` (power per metre per band [W/m-like], kernels [1/m], distances [m]).
    lpafmax_dba : ndarray, optional
        LpAFmax per pass [dB(A)] (None: NaN).

    Returns
    -------
    PassBy
        The levels per band and per pass [dB re 20 uPa, dB(A)] and Tp [s].

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.6-3.9.
    """
    mean = _per_line(w * k for w, k, _, _ in paths)   # mean squared pressure over the pass-by time
    exposure = _per_line(w * total for w, _, total, _ in paths)
    a = g.a_weight
    return PassBy(
        lp_db=level(mean),
        lpaeq_tp_dba=level(np.sum(mean * a, axis=-1)),
        tel_dba=level(np.sum(exposure * a, axis=-1)),
        lpafmax_dba=np.full(len(g.length), np.nan) if lpafmax_dba is None else lpafmax_dba,
        pass_by_time_s=g.length / g.speed,
    )


def _per_line(terms: Iterator[FloatArray]) -> FloatArray:
    """Sum of the paths' terms, the direct and image paths of each source line first."""
    terms = list(terms)
    out = terms[0] + terms[1]
    return out if len(terms) == 2 else out + (terms[2] + terms[3])


