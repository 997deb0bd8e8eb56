"""Wear-type corrugation growth per wheel pass (UQ paper section 2.1, eqs. 1-2; docs/models.md).

A rail roughness harmonic of wavelength lambda [m], passed at speed V [m/s] (frequency
f = V / lambda), grows per wheel pass by

    Z_{n+1} / Z_n = 1 + K_b H(f),      H = 1 / (1 + k_c (R_r(f) + R_w(f)))

with k_c the linearised Hertz contact stiffness [N/m] (models.hertz), R_r and R_w the complex
vertical receptances of rail and wheel [m/N] (models.track) and K_b the wear sensitivity [-]
(order 1e-5 per pass; the field-tuning parameter). Over a distribution p(V) of pass speeds the
expected log growth per pass is (UQ paper eq. 2, kept in its ln|.| form, not linearised)

    g(lambda) = integral ln|1 + K_b H(V / lambda)| p(V) dV,      Z_n ~ Z_0 exp(n g).

The UQ paper's eq. (1) is a single-mode approximation, G_r = K_b (1 + K_c / (4 zeta (1 + zeta))),
valid only as K_c -> 0; :func:`single_mode_growth_max` is the exact maximum of K_b Re H for one
mode (docs/models.md), and the tests check both against the full kernel.

Two additions to the UQ paper's kernel, both cited where they are defined:
- the contact filter F (models.contact_filter) acts twice, on the roughness the contact sees and
  on the wear it leaves, so the growth term is K_b F^2 H; without it every wavelength shorter than
  the contact patch would grow at K_b at least (H -> 1 as the receptances vanish);
- a band is tracked as components at wavelengths spread across it (:func:`band_sub_wavelengths`),
  each growing at its own rate; the band's r.m.s. is their energy sum (:func:`band_amplitude`)
  and tends to grow at the rate of its fastest component, so a resonance between band centres
  is not missed.

Grinding limits (Grassie, Saxon & Smith, J. Sound Vib. 227 (1999) 949-964) are here too; the
speed plan (a linear programme) is :mod:`rail_monitor.advice.speed_plan`.

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and acoustic
   phenomena", seminar paper, section 2.1 (eqs. 1-2, Figure 2).
.. [2] S. L. Grassie, M. J. Saxon and J. D. Smith, "Measurement of longitudinal rail irregularities and
   criteria for acceptable grinding", *Journal of Sound and Vibration* 227(5) (1999) 949-964.
.. [3] A. Hempelmann and K. Knothe, "An extended linear model for the prediction of short pitch
   corrugation", *Wear* 191 (1996) 161-169.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def wavelength_bands(shortest_m: float = 0.01, longest_m: float = 1.0) -> FloatArray:
    """1/3-octave wavelength band centres covering a range, base ten.

    The centres are 10^(n/10) m, as IEC 61260-1's exact mid-band frequencies are 10^(n/10) Hz.

    Parameters
    ----------
    shortest_m : float
        Shortest wavelength to cover [m].
    longest_m : float
        Longest wavelength to cover [m].

    Returns
    -------
    ndarray
        Band centres [m], ascending.

    References
    ----------
    .. [1] IEC 61260-1:2014, Electroacoustics - Octave-band and fractional-octave-band filters, 5.2-5.4.
    """
    lo = int(np.floor(10 * np.log10(shortest_m) + 1e-9))
    hi = int(np.ceil(10 * np.log10(longest_m) - 1e-9))
    return 10.0 ** (np.arange(lo, hi + 1) / 10.0)


def band_sub_wavelengths(centres: ArrayLike, per_band: int = 5) -> FloatArray:
    """Wavelengths spread evenly in log across each 1/3-octave band.

    Band edges are centre x 10^(+-1/20); the points are the centres of per_band equal log slices,
    so a resonance between band centres is not missed.

    Parameters
    ----------
    centres : array_like
        Band centres [m].
    per_band : int
        Components per band [-].

    Returns
    -------
    ndarray
        Wavelengths [m], shape (bands, per_band).

    References
    ----------
    .. [1] IEC 61260-1:2014, Electroacoustics - Octave-band and fractional-octave-band filters, 5.2-5.4 (band edges).
    """
    c = np.asarray(centres, float)[:, None]
    u = (np.arange(per_band) + 0.5) / per_band - 0.5
    return c * 10.0 ** (u[None, :] / 10.0)


def growth_kernel(contact_stiffness: ArrayLike, receptance_sum: ArrayLike) -> ComplexArray:
    """The growth kernel H = 1 / (1 + k_c (R_r + R_w)) of UQ eq. 2.

    Parameters
    ----------
    contact_stiffness : array_like
        Linearised Hertz contact stiffness k_c [N/m].
    receptance_sum : array_like
        Vertical receptance of rail plus wheel, R_r + R_w [m/N] (complex).

    Returns
    -------
    ndarray of complex
        H [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    return 1.0 / (1.0 + np.asarray(contact_stiffness) * np.asarray(receptance_sum))


def log_growth_per_pass(wear_sensitivity: ArrayLike, kernel: ArrayLike) -> FloatArray:
    """The log amplitude growth of one wheel pass, ln|1 + K_b H|.

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b [-].
    kernel : array_like
        H [-] (complex; :func:`growth_kernel`).

    Returns
    -------
    ndarray
        ln|1 + K_b H| [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    return np.log(np.abs(1.0 + np.asarray(wear_sensitivity) * np.asarray(kernel)))


def expected_log_growth(
    wear_sensitivity: float,
    kernel_at: Callable[[FloatArray], ComplexArray],
    wavelengths: ArrayLike,
    speeds: ArrayLike,
    weights: ArrayLike,
) -> FloatArray:
    """The expected log growth per pass g(lambda) over a discrete speed distribution (UQ eq. 2).

    g(lambda) = sum_i w_i ln|1 + K_b H(V_i / lambda)|, the ln|.| form kept, not linearised.

    Parameters
    ----------
    wear_sensitivity : float
        K_b [-].
    kernel_at : callable
        H [-] at frequencies f [Hz] (any shape).
    wavelengths : array_like
        Wavelengths lambda [m].
    speeds : array_like
        Pass speeds V_i [m/s].
    weights : array_like
        Their probabilities w_i [-] (summing to 1).

    Returns
    -------
    ndarray
        g [1/pass], one value per wavelength.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    """
    lam = np.asarray(wavelengths, float)[:, None]
    v = np.asarray(speeds, float)[None, :]
    w = np.asarray(weights, float)
    if not np.isclose(w.sum(), 1.0):
        raise ValueError("speed weights must sum to 1")
    return log_growth_per_pass(wear_sensitivity, kernel_at(v / lam)) @ w


def single_mode_kernel(frequency_ratio: ArrayLike, contact_ratio: ArrayLike, damping_ratio: ArrayLike) -> ComplexArray:
    """H for one combined wheel/rail mode: R = 1 / (k (1 - r^2 + 2 i zeta r)), K_c = k_c / k.

    Parameters
    ----------
    frequency_ratio : array_like
        r = f / f_n [-].
    contact_ratio : array_like
        K_c = k_c / k [-].
    damping_ratio : array_like
        zeta [-].

    Returns
    -------
    ndarray of complex
        H of the one mode [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eqs. 1-2.
    """
    r = np.asarray(frequency_ratio, float)
    return 1.0 / (1.0 + np.asarray(contact_ratio) / (1.0 - r * r + 2j * np.asarray(damping_ratio) * r))


def single_mode_growth_approx(wear_sensitivity: ArrayLike, contact_ratio: ArrayLike,
                            damping_ratio: ArrayLike) -> FloatArray:
    """The UQ paper's eq. (1): G_r = K_b (1 + K_c / (4 zeta (1 + zeta))), the K_c -> 0 limit.

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b [-].
    contact_ratio : array_like
        K_c [-].
    damping_ratio : array_like
        zeta [-].

    Returns
    -------
    ndarray
        G_r [1/pass].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 1.
    """
    z = np.asarray(damping_ratio, float)
    return np.asarray(wear_sensitivity) * (1.0 + np.asarray(contact_ratio) / (4.0 * z * (1.0 + z)))


def single_mode_growth_max(wear_sensitivity: ArrayLike, contact_ratio: ArrayLike,
                           damping_ratio: ArrayLike) -> FloatArray:
    """Exact maximum over frequency of K_b Re H for one mode (docs/models.md).

    K_b [1 + K_c / (4 z (1 + z) (1 + K_c))], z = zeta / sqrt(1 + K_c): the contact spring raises the
    mode's frequency and lowers its damping ratio; as K_c -> 0 it tends to the UQ paper's eq. (1).

    Parameters
    ----------
    wear_sensitivity, contact_ratio, damping_ratio : array_like
        K_b [-], K_c = k_c / k [-] and the mode's damping ratio zeta [-], as for
        :func:`single_mode_growth_approx`.

    Returns
    -------
    ndarray
        The peak growth rate [1/pass].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 1 (which this corrects for finite K_c).
    """
    kc = np.asarray(contact_ratio, float)
    z = np.asarray(damping_ratio, float) / np.sqrt(1.0 + kc)
    return np.asarray(wear_sensitivity) * (1.0 + kc / (4.0 * z * (1.0 + z) * (1.0 + kc)))


SLIDING_WEAR_EXPONENT = 2.0 / 3.0  # beta = d ln w / d ln N in full sliding (docs/models.md, "Sliding")


def sliding_wear_sensitivity(wear_sensitivity: ArrayLike, wear_ratio: ArrayLike = 1.0) -> FloatArray:
    """K_b in full sliding from K_b in partial slip: -(2/3) K_b w_slide / w_slip.

    Wear proportional to frictional power gives K_b = -beta k_c w / N with beta = d ln w / d ln N
    (w the mean wear per pass at the static load N, k_c the contact stiffness). In partial slip at
    a prescribed tangential force more load means less slip, beta = -1 and K_b = k_c w / N > 0;
    in full sliding the wear depth is mu p times the slip distance, p ~ N / (a b) and a, b ~ N^(1/3)
    [2]_, so w ~ N^(2/3), beta = +2/3 and K_b = -(2/3) k_c w / N.

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b in partial slip [-].
    wear_ratio : array_like
        Mean wear per pass in full sliding over that in partial slip at the same friction state [-].

    Returns
    -------
    ndarray
        K_b in full sliding [-].

    References
    ----------
    .. [1] A. Hempelmann and K. Knothe, "An extended linear model for the prediction of short pitch
       corrugation", *Wear* 191 (1996) 161-169 (wear proportional to frictional power).
    .. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, section 4.2.
    """
    return -SLIDING_WEAR_EXPONENT * np.asarray(wear_ratio, float) * np.asarray(wear_sensitivity, float)


def filtered_log_growth(wear_sensitivity: ArrayLike, kernel: ArrayLike, contact_filter: ArrayLike) -> FloatArray:
    """One wheel pass's log growth with the contact filter, ln|1 + K_b F^2 H|.

    F acts twice: on the roughness the contact sees and on the wear it leaves (models.contact_filter).

    Parameters
    ----------
    wear_sensitivity : array_like
        K_b [-].
    kernel : array_like
        H [-] (complex).
    contact_filter : array_like
        F [-].

    Returns
    -------
    ndarray
        ln|1 + K_b F^2 H| [-].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.1, eq. 2.
    .. [2] A. Hempelmann and K. Knothe, "An extended linear model for the prediction of short pitch
       corrugation", *Wear* 191 (1996) 161-169 (the contact filter).
    """
    f = np.asarray(contact_filter)
    return log_growth_per_pass(wear_sensitivity, f * f * np.asarray(kernel))


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


# Post-grinding acceptance limits of Grassie, Saxon & Smith (1999), r.m.s. roughness per
# wavelength range: ((shortest [m], longest [m]), limit [m]).
GRASSIE_1999_LIMITS: tuple[tuple[tuple[float, float], float], ...] = (
    ((0.01, 0.03), 3e-6),
    ((0.03, 0.10), 7e-6),
    ((0.10, 0.30), 7e-6),
    ((0.30, 1.00), 45e-6),
    ((1.00, 3.00), 100e-6),
)


def band_limits(centres: ArrayLike, ranges=GRASSIE_1999_LIMITS) -> FloatArray:
    """Per-band r.m.s. limit from range limits (default Grassie et al. 1999).

    A range's limit is shared equally by the energy of its 1/3-octave bands: a band gets
    limit / sqrt(n), n the number of base-10 band centres in [shortest, longest), so a range whose
    bands all sit at their limit has exactly the range's r.m.s. Bands outside every range get NaN.

    Parameters
    ----------
    centres : array_like
        Band centres [m].
    ranges : sequence of ((float, float), float)
        ((shortest [m], longest [m]), r.m.s. limit [m]) per wavelength range.

    Returns
    -------
    ndarray
        Limit per band [m] (NaN outside every range).

    References
    ----------
    .. [1] S. L. Grassie, M. J. Saxon and J. D. Smith, "Measurement of longitudinal rail irregularities
       and criteria for acceptable grinding", *Journal of Sound and Vibration* 227(5) (1999) 949-964.
    """
    c = np.asarray(centres, float)
    out = np.full(c.shape, np.nan)
    def inside(x: FloatArray, lo: float, hi: float) -> NDArray[np.bool_]:
        return (x >= lo * (1 - 1e-9)) & (x < hi * (1 - 1e-9))

    for (lo, hi), limit in ranges:
        n = int(inside(wavelength_bands(lo, hi), lo, hi).sum())
        out[inside(c, lo, hi)] = limit / np.sqrt(n)
    return out
