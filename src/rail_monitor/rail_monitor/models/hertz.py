"""Elliptical Hertz contact of two elastic bodies (non-conformal, frictionless normal problem).

Axes: x is the rolling direction, y the lateral direction. Each body is described by its
principal radii of curvature in x and in y at the contact point (positive convex, negative
concave, ``inf`` for straight). The contact patch is an ellipse of semi-axes ``a`` (along x)
and ``b`` (along y) carrying the pressure p = p0 sqrt(1 - x^2/a^2 - y^2/b^2).

References
----------
K. L. Johnson, *Contact Mechanics*, Cambridge University Press 1985, section 4.2 and
eqs. (3.60)-(3.64): relative curvatures A, B; for the ellipse with major semi-axis a_1, minor
b_1 and eccentricity e (m = e^2) under total load P,

    A_1 = (p0 / E*) (b_1 / (e^2 a_1^2)) (K(e) - E(e))               (curvature along a_1)
    B_1 = (p0 / E*) (b_1 / (e^2 a_1^2)) ((a_1/b_1)^2 E(e) - K(e))
    delta = (p0 / E*) b_1 K(e),     P = (2/3) pi a_1 b_1 p0,

with K, E the complete elliptic integrals of the first and second kind and
1/E* = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2. The ratio B_1/A_1 fixes e; the load then scales
every length as P^(1/3).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import ellipe, ellipkm1

FloatArray = NDArray[np.float64]


class HertzContact(NamedTuple):
    """Solution of the Hertz problem (arrays broadcast over the inputs).

    a: semi-axis along the rolling direction x [m]; b: semi-axis along y [m];
    p0: peak pressure [Pa]; approach: mutual approach of distant points delta [m];
    stiffness: linearised normal contact stiffness dP/d(delta) = 3 P / (2 delta) [N/m];
    e_star: contact modulus E* [Pa].
    """

    a: FloatArray
    b: FloatArray
    p0: FloatArray
    approach: FloatArray
    stiffness: FloatArray
    e_star: FloatArray


def contact_modulus(
    e1: ArrayLike, nu1: ArrayLike, e2: ArrayLike | None = None, nu2: ArrayLike | None = None
) -> FloatArray:
    """Contact modulus E* of two elastic bodies, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2.

    With only the first body given, both bodies are of the same material.

    Parameters
    ----------
    e1 : array_like
        Young's modulus of body 1 [Pa].
    nu1 : array_like
        Poisson's ratio of body 1 [-].
    e2 : array_like, optional
        Young's modulus of body 2 [Pa] (default: e1).
    nu2 : array_like, optional
        Poisson's ratio of body 2 [-] (default: nu1).

    Returns
    -------
    ndarray
        E* [Pa].

    References
    ----------
    .. [1] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, Cambridge, 1985, eq. (3.64).
    """
    e1, nu1 = np.asarray(e1, float), np.asarray(nu1, float)
    e2 = e1 if e2 is None else np.asarray(e2, float)
    nu2 = nu1 if nu2 is None else np.asarray(nu2, float)
    return 1.0 / ((1.0 - nu1**2) / e1 + (1.0 - nu2**2) / e2)


def _ratio_for_axis_ratio(k: float) -> float:
    """Curvature ratio B_1/A_1 (>= 1) of the ellipse of minor/major axis ratio k (0 < k < 1)."""
    p = k * k  # complementary parameter 1 - m; ellipkm1 keeps precision as m -> 1
    m = 1.0 - p
    kk, ee = ellipkm1(p), ellipe(m)
    return (ee / p - kk) / (kk - ee)


@lru_cache(maxsize=4096)  # a site has a handful of geometries; the live graph asks once per pass
def _axis_ratio(curvature_ratio: float) -> float:
    """Minor/major axis ratio k of the contact ellipse for a curvature ratio B_1/A_1 >= 1."""
    if curvature_ratio <= 1.0 + 1e-12:
        return 1.0
    # B_1/A_1 grows monotonically as k falls: bisect in log k between k = 1e-6 (ratio ~ 1e10) and
    # k = 1 - 1e-9 until the bracket is two adjacent doubles (about 60 halvings, once per geometry;
    # scipy.optimize would cost 23 MB and 0.3 s to import in every node).
    target = np.log(curvature_ratio)
    lo, hi = np.log(1e-6), np.log(1.0 - 1e-9)    # ratio(lo) > target > ratio(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            break
        if np.log(_ratio_for_axis_ratio(np.exp(mid))) > target:
            lo = mid
        else:
            hi = mid
    return float(np.exp(0.5 * (lo + hi)))


def _k_minus_e_over_m(k: FloatArray) -> FloatArray:
    """(K(e) - E(e)) / e^2 for axis ratio k, with its circular limit pi/4."""
    p = k * k
    m = 1.0 - p
    safe = np.where(m > 1e-10, m, 1.0)
    return np.where(m > 1e-10, (ellipkm1(p) - ellipe(m)) / safe, np.pi / 4.0)


@lru_cache(maxsize=4096)
def _shape_of(curvature_ratio: float) -> tuple[float, float, float]:
    """What the ellipse's shape alone fixes, for a curvature ratio B_1/A_1: the axis ratio k,
    (K - E)/e^2 and K (once per geometry)."""
    k = np.array(_axis_ratio(curvature_ratio))
    return float(k), float(_k_minus_e_over_m(k)), float(ellipkm1(k * k))


def _shapes(ratio: FloatArray) -> FloatArray:
    """_shape_of over an array of curvature ratios (shape + (3,)); a site has a few geometries."""
    r = np.round(ratio, 12).ravel()
    uniq, inverse = (r, np.zeros(1, np.intp)) if r.size == 1 else np.unique(r, return_inverse=True)
    return np.array([_shape_of(x) for x in uniq.tolist()]).reshape(-1, 3)[inverse].reshape(*ratio.shape, 3)


def contact_ellipse(
    r1x: ArrayLike,
    r1y: ArrayLike,
    r2x: ArrayLike,
    r2y: ArrayLike,
    e_star: ArrayLike,
    load: ArrayLike,
) -> HertzContact:
    """Hertz contact ellipse of two bodies with aligned principal axes.

    The elliptic-integral solution is exact; the axis ratio depends on the geometry only, so it is
    solved once per distinct geometry.

    Parameters
    ----------
    r1x, r1y, r2x, r2y : array_like
        Principal radii of curvature of bodies 1 and 2 along the rolling direction x and the
        lateral direction y [m] (negative: concave; ``np.inf``: straight).
    e_star : array_like
        Contact modulus E* [Pa] (:func:`contact_modulus`).
    load : array_like
        Normal load P [N] (> 0).

    Returns
    -------
    HertzContact
        Semi-axes a along x and b along y [m], peak pressure p0 [Pa], approach [m] and the
        linearised contact stiffness [N/m].

    References
    ----------
    .. [1] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, Cambridge, 1985,
       section 4.2, eqs. (3.60)-(3.64).
    """
    r1x, r1y, r2x, r2y, e_star, load = (np.asarray(v, float) for v in (r1x, r1y, r2x, r2y, e_star, load))
    curv_x = 0.5 * (1.0 / r1x + 1.0 / r2x)
    curv_y = 0.5 * (1.0 / r1y + 1.0 / r2y)
    if (curv_x <= 0.0).any() or (curv_y <= 0.0).any():
        raise ValueError("relative curvature must be positive in x and y (the bodies must touch at a point)")
    if (~(load > 0.0)).any():
        raise ValueError("normal load must be positive")
    c_major_axis = np.minimum(curv_x, curv_y)  # the longer semi-axis lies along the smaller curvature
    shape = _shapes(np.maximum(curv_x, curv_y) / c_major_axis)
    k, k_minus_e_over_m, k_integral = shape[..., 0], shape[..., 1], shape[..., 2]

    major = np.cbrt(3.0 * load * k_minus_e_over_m / (2.0 * np.pi * e_star * c_major_axis))
    minor = k * major
    p0 = 3.0 * load / (2.0 * np.pi * major * minor)
    approach = p0 * minor * k_integral / e_star
    along_x = curv_x <= curv_y
    a = np.where(along_x, major, minor)
    b = np.where(along_x, minor, major)
    e_star = np.broadcast_to(e_star, a.shape)
    return HertzContact(a, b, p0, approach, 1.5 * load / approach, e_star)
