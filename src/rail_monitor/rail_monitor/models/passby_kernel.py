"""The kernel of a pass-by: the squared pressure of a moving incoherent line source at a wayside
receiver, its antiderivatives along the track, and the F time weighting of its time history (no
rclpy). Shared by the line source (models.passby) and the point source per axle
(models.passby_axles and its compiled twin).

A unit source element at x along the track, horizontal distance d and perpendicular path distance
R = sqrt(d^2 + dz^2), radiates with CNOSSOS-EU's rolling-noise directivity
D(phi) = OMNI + BROADSIDE sin^2 phi (Directive (EU) 2015/996 Annex II eq. 2.3.15) under spherical
spreading Lp = L_W - 10 lg(4 pi r^2) (Annex II 2.5.6):

    g(x) = [OMNI / (R^2 + x^2) + BROADSIDE d^2 / ((d^2 + x^2)(R^2 + x^2))] / (4 pi)   [1/m^2]

The F time weighting is IEC 61672-1:2013's exponential average (eq. 7, tau = 0.125 s, 5.8).

References
----------
.. [1] Commission Directive (EU) 2015/996 of 19 May 2015 establishing common noise assessment methods
   according to Directive 2002/49/EC, *Official Journal of the European Union* L 168, 1.7.2015,
   Annex II sections 2.3 and 2.5.
.. [2] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*,
   International Electrotechnical Commission, Geneva, 2013.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

F_TIME_CONSTANT_S = 0.125   # IEC 61672-1:2013, 5.8: time weighting F
OMNI, BROADSIDE = 0.01, 0.99  # the directivity's omnidirectional and sin^2 phi weights (Annex II eq. 2.3.15)
FEW_ROWS = 8  # below this many series a Python loop beats numpy's per-call overhead


# The paths of a pass-by: (A-weighted power per metre per pass [any unit], perpendicular distance [m]).
Paths = list[tuple[FloatArray, float]]


def _atan_over(x: FloatArray, c: float) -> FloatArray:
    """Antiderivative of 1 / (c^2 + x^2): atan(x / c) / c."""
    return np.arctan(x / c) / c


def _atan_over_integral(x: FloatArray, c: float) -> FloatArray:
    """Antiderivative of atan(x / c) / c: (x atan(x / c) - (c / 2) ln(c^2 + x^2)) / c."""
    return (x * np.arctan(x / c) - 0.5 * c * np.log(c * c + x * x)) / c


def same_path(d: float, r: float) -> bool:
    """Whether R = d to within 1e-6 d^2: no height difference, the broadside term's limit form.

    Parameters
    ----------
    d, r : float
        Horizontal distance and path distance [m].

    Returns
    -------
    bool
        [-]

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eq. 2.3.15.
    """
    return r * r - d * d < 1e-6 * d * d


def point_kernel(x: ArrayLike, d: float, r: float) -> FloatArray:
    """g(x), the squared pressure re rho c of a unit point source at x along the track.

    g(x) = [OMNI / (R^2 + x^2) + BROADSIDE d^2 / ((d^2 + x^2)(R^2 + x^2))] / (4 pi).

    Parameters
    ----------
    x : array_like
        Position along the track from the receiver's perpendicular [m].
    d : float
        Horizontal distance [m].
    r : float
        Path distance R [m].

    Returns
    -------
    ndarray
        g [1/m^2].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eq. 2.3.15 and 2.5.6.
    """
    x2 = np.asarray(x, float) ** 2
    q = d * d + x2
    return (OMNI * q + BROADSIDE * d * d) / (q * (r * r + x2) * (4.0 * np.pi))


def kernel_antiderivative(x: ArrayLike, d: float, r: float) -> FloatArray:
    """G(x), the integral of g from 0 to x.

    Parameters
    ----------
    x, d, r : array_like, float, float
        As for :func:`point_kernel`: position along the track, horizontal distance and path
        distance R [m].

    Returns
    -------
    ndarray
        G [1/m].

    References
    ----------
    .. [1] Commission Directive (EU) 2015/996 (OJ L 168, 1.7.2015), Annex II, eqs. 2.3.15 and 2.5.6
       (the kernel integrated).
    """
    x = np.asarray(x, float)
    return _antiderivative_with(x, d, r, _atan_over(x, d))


def _antiderivative_with(x: FloatArray, d: float, r: float, at_d: FloatArray) -> FloatArray:
    """G(x) given at_d = _atan_over(x, d), which the direct and image paths share at the same x
    (the arctangents are most of a pass-by's cost; each is computed once)."""
    at_r = _atan_over(x, r)
    # R = d: d^2 / (d^2 + x^2)^2 integrates to x / (2 (d^2 + x^2)) + atan(x/d) / (2 d)
    broad = (0.5 * x / (d * d + x * x) + 0.5 * at_d if same_path(d, r)
             else d * d * (at_d - at_r) / (r * r - d * d))
    return (OMNI * at_r + BROADSIDE * broad) / (4.0 * np.pi)


def kernel_second_antiderivative(x: ArrayLike, d: float, r: float) -> FloatArray:
    """GG(x), an antiderivative of G(x) (even in x), for window means of G.

    Parameters
    ----------
    x, d, r : array_like, float, float
        Position along the track [m], horizontal distance [m] and path distance R [m].

    Returns
    -------
    ndarray
        GG [-].

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.9 (the mean over the pass-by time it gives).
    """
    x = np.asarray(x, float)
    if same_path(d, r):
        broad = 0.25 * np.log(d * d + x * x) + 0.5 * _atan_over_integral(x, d)
    else:
        broad = d * d * (_atan_over_integral(x, d) - _atan_over_integral(x, r)) / (r * r - d * d)
    return (OMNI * _atan_over_integral(x, r) + BROADSIDE * broad) / (4.0 * np.pi)


def kernel_total(d: float, r: float) -> float:
    """The integral of g over all x: [0.01 / R + 0.99 d / (R (d + R))] / 4.

    Parameters
    ----------
    d, r : float
        Horizontal distance and path distance R [m], as for :func:`point_kernel`.

    Returns
    -------
    float
        Total [1/m].

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.8 (TEL takes the whole pass's energy).
    """
    return (OMNI / r + BROADSIDE * d / (r * (d + r))) / 4.0


def kernel_window_mean(length_m: ArrayLike, d: float, r: float) -> FloatArray:
    """Mean over the pass-by time of the kernel of a line of length L.

    Parameters
    ----------
    length_m : array_like
        Train length L [m].
    d, r : float
        The receiver's horizontal distance and the path's distance R [m].

    Returns
    -------
    ndarray
        Window mean [1/m].

    References
    ----------
    .. [1] ISO 3095:2013, *Acoustics - Railway applications - Measurement of noise emitted by
       railbound vehicles*, 3.9 (LpAeq,Tp over Tp = L / v).
    """
    length = np.asarray(length_m, float)
    gg = kernel_second_antiderivative
    return (gg(length, d, r) - 2.0 * gg(0.0, d, r) + gg(-length, d, r)) / length


def exponential_average(x: FloatArray, a: float | FloatArray) -> FloatArray:
    """The sampled exponential time weighting y_n = (1 - a) x_n + a y_(n-1), started in steady state.

    Along the last axis, y_(-1) = x_0; a = exp(-dt / tau), one for all series or one per series
    (x's leading shape). The arithmetic of scipy.signal.lfilter([1 - a], [1, -a], x, zi=a x_0),
    step for step (the tests compare the bits), without importing scipy.signal at a node's start-up.

    Parameters
    ----------
    x : ndarray
        The series [any unit].
    a : float or ndarray
        exp(-dt / tau) [-].

    Returns
    -------
    ndarray
        The weighted series [x's unit].

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, eq. 7.
    """
    rows = np.asarray(x, float).reshape(-1, np.shape(x)[-1])
    a_rows = np.broadcast_to(np.asarray(a, float), np.shape(x)[:-1]).reshape(-1)
    b0 = 1.0 - a_rows
    if len(rows) <= FEW_ROWS:  # a live pass: plain floats, the same IEEE operations
        out = []
        for row, ar, br in zip(rows.tolist(), a_rows.tolist(), b0.tolist(), strict=True):
            state, ys = ar * row[0], []
            for v in row:
                y = br * v + state
                ys.append(y)
                state = ar * y
            out.append(ys)
        return np.array(out, float).reshape(np.shape(x))
    xt = np.ascontiguousarray(rows.T)  # time-major: each step is one contiguous row
    yt = np.empty_like(xt)
    state = a_rows * xt[0]
    for n in range(len(xt)):
        np.multiply(b0, xt[n], out=yt[n])
        yt[n] += state
        state = a_rows * yt[n]
    return yt.T.reshape(np.shape(x))


def line_f_weighted_peak(paths: Paths, length: FloatArray, speed: FloatArray, d: float,
                     steps_per_tau: int = 8) -> FloatArray:
    """Peak of the F-time-weighted squared pressure of a moving line over its paths.

    sum_i c_i x_i(t), x_i(t) = G_i(vt) - G_i(vt - L); exponential averaging (tau = 0.125 s) from 6 tau
    before to 3 tau after the unweighted peak (the train's middle at the perpendicular), started in
    steady state: the truncated history weighs e^-6 of a level no higher than the peak's.

    Parameters
    ----------
    paths : Paths
        (c [W/m-like], R [m]) per path.
    length, speed : ndarray
        Train length [m] and speed [m/s] per pass.
    d : float
        Horizontal distance [m].
    steps_per_tau : int
        Time steps per time constant [-].

    Returns
    -------
    ndarray
        Peak squared pressure per pass [the paths' unit over m].

    References
    ----------
    .. [1] IEC 61672-1:2013, *Electroacoustics - Sound level meters - Part 1: Specifications*, 5.8 and eq. 7.
    """
    tau = F_TIME_CONSTANT_S
    t = (np.arange(-6 * steps_per_tau, 3 * steps_per_tau + 1) / steps_per_tau) * tau
    s = 0.5 * length[:, None] + speed[:, None] * t[None, :]     # front position along the track [m]
    g = _antiderivative_with
    rear = s - length[:, None]
    front_d, rear_d = _atan_over(s, d), _atan_over(rear, d)  # shared by every path
    x = None
    for c, r in paths:
        term = c[:, None] * (g(s, d, r, front_d) - g(rear, d, r, rear_d))
        x = term if x is None else x + term
    return exponential_average(x, np.exp(-1.0 / steps_per_tau)).max(axis=1)
