"""Kalker's linear-theory creep coefficients C11, C22, C23 for elliptical contact.

The linear creep forces are F_x = -G a b C11 xi, F_y = -G a b (C22 eta + sqrt(ab) C23 phi),
with G the shear modulus, a (rolling) and b (lateral) the Hertz semi-axes, and xi, eta, phi the
longitudinal, lateral and spin creepages.

Table values: J. J. Kalker, *Three-Dimensional Elastic Bodies in Rolling Contact*, Kluwer 1990,
Appendix E, Table E.3 (the same numbers as Kalker's 1967 thesis and Johnson 1985, Table 8.1),
for Poisson's ratio 0, 0.25, 0.5 and g = a/b (a <= b) or g = b/a (a > b) from 0.1 to 1.

Interpolation (our choice, documented): linear in ln(a/b) between table rows, then a quadratic
through the three Poisson's ratios. Outside 0.1 <= a/b <= 10 a ValueError is raised rather
than extrapolating.

References
----------
.. [1] J. J. Kalker, *Three-Dimensional Elastic Bodies in Rolling Contact*, Kluwer Academic Publishers,
   Dordrecht, 1990, Appendix E, Table E.3.
.. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, Cambridge, 1985, Table 8.1.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

TABLE_NU = (0.0, 0.25, 0.5)

# Kalker (1990) Table E.3. Rows: a/b; columns: C11, C22, C23, each for nu = 0, 0.25, 0.5.
_A_OVER_B = np.array(
    [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0,
     1 / 0.9, 1 / 0.8, 1 / 0.7, 1 / 0.6, 1 / 0.5, 1 / 0.4, 1 / 0.3, 1 / 0.2, 1 / 0.1]
)  # fmt: skip
_TABLE = np.array(
    [
        # a <= b, g = a/b = 0.1 ... 1.0
        [2.51, 3.31, 4.85, 2.51, 2.52, 2.53, 0.334, 0.473, 0.731],
        [2.59, 3.37, 4.81, 2.59, 2.63, 2.66, 0.483, 0.603, 0.809],
        [2.68, 3.44, 4.80, 2.68, 2.75, 2.81, 0.607, 0.715, 0.889],
        [2.78, 3.53, 4.82, 2.78, 2.88, 2.98, 0.720, 0.823, 0.977],
        [2.88, 3.62, 4.83, 2.88, 3.01, 3.14, 0.827, 0.929, 1.07],
        [2.98, 3.72, 4.91, 2.98, 3.14, 3.31, 0.930, 1.03, 1.18],
        [3.09, 3.81, 4.97, 3.09, 3.28, 3.48, 1.03, 1.14, 1.29],
        [3.19, 3.91, 5.05, 3.19, 3.41, 3.65, 1.13, 1.25, 1.40],
        [3.29, 4.01, 5.12, 3.29, 3.54, 3.82, 1.23, 1.36, 1.51],
        [3.40, 4.12, 5.20, 3.40, 3.67, 3.98, 1.33, 1.47, 1.63],
        # a > b, g = b/a = 0.9 ... 0.1
        [3.51, 4.22, 5.30, 3.51, 3.81, 4.16, 1.44, 1.59, 1.77],
        [3.65, 4.36, 5.42, 3.65, 3.99, 4.39, 1.58, 1.75, 1.94],
        [3.82, 4.54, 5.58, 3.82, 4.21, 4.67, 1.76, 1.95, 2.18],
        [4.06, 4.78, 5.80, 4.06, 4.50, 5.04, 2.01, 2.23, 2.50],
        [4.37, 5.10, 6.11, 4.37, 4.90, 5.56, 2.35, 2.62, 2.96],
        [4.84, 5.57, 6.57, 4.84, 5.48, 6.31, 2.88, 3.24, 3.70],
        [5.57, 6.34, 7.34, 5.57, 6.40, 7.51, 3.79, 4.32, 5.01],
        [6.96, 7.78, 8.82, 6.96, 8.14, 9.79, 5.72, 6.63, 7.89],
        [10.7, 11.7, 12.9, 10.7, 12.8, 16.0, 12.2, 14.6, 18.0],
    ]
).reshape(19, 3, 3)  # [row, coefficient (C11, C22, C23), nu]


class CreepCoefficients(NamedTuple):
    """Kalker's linear coefficients [-] (arrays broadcast over the inputs)."""

    c11: FloatArray
    c22: FloatArray
    c23: FloatArray


def creep_coefficients(a_over_b: ArrayLike, nu: ArrayLike) -> CreepCoefficients:
    """Kalker's linear creep coefficients C11, C22, C23 of an elliptical contact.

    Interpolated linearly in ln(a/b) and quadratically in nu (0 <= nu <= 0.5) from Kalker's table;
    exact at the table's nodes. Outside 0.1 <= a/b <= 10 a ValueError is raised.

    Parameters
    ----------
    a_over_b : array_like
        Ellipse ratio a/b, a along rolling [-].
    nu : array_like
        Poisson's ratio [-].

    Returns
    -------
    CreepCoefficients
        C11, C22, C23 [-].

    References
    ----------
    .. [1] J. J. Kalker, *Three-Dimensional Elastic Bodies in Rolling Contact*, Kluwer Academic
       Publishers, Dordrecht, 1990, Appendix E, Table E.3.
    .. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, Cambridge, 1985, Table 8.1.
    """
    c = _interpolated(a_over_b, nu, (0, 1, 2))
    return CreepCoefficients(c[..., 0], c[..., 1], c[..., 2])


def lateral_creep_coefficient(a_over_b: ArrayLike, nu: ArrayLike) -> FloatArray:
    """Kalker's lateral creep coefficient C22 alone, as :func:`creep_coefficients` gives it.

    Parameters
    ----------
    a_over_b, nu : array_like
        As for :func:`creep_coefficients`: the ellipse ratio a/b [-] and Poisson's ratio [-].

    Returns
    -------
    ndarray
        C22 [-].

    References
    ----------
    .. [1] J. J. Kalker, *Three-Dimensional Elastic Bodies in Rolling Contact*, Kluwer Academic
       Publishers, Dordrecht, 1990, Appendix E, Table E.3.
    """
    return _interpolated(a_over_b, nu, (1,))[..., 0]


def _interpolated(a_over_b: ArrayLike, nu: ArrayLike, coefficients: tuple[int, ...]) -> FloatArray:
    """The table's coefficients (indices into C11, C22, C23) at (a/b, nu): shape (..., coefficients)."""
    ratio, nu = np.broadcast_arrays(np.asarray(a_over_b, float), np.asarray(nu, float))
    if np.any(~((ratio >= 0.1 - 1e-12) & (ratio <= 10.0 + 1e-9))):
        raise ValueError("Kalker's table covers 0.1 <= a/b <= 10")
    if np.any(~((nu >= 0.0) & (nu <= 0.5))):
        raise ValueError("Poisson's ratio must lie in [0, 0.5]")
    x = np.log(_A_OVER_B)
    lx = np.log(np.clip(ratio, 0.1, 10.0))
    # Interpolate each wanted (coefficient, nu) column in ln(a/b): shape (..., coefficients, 3).
    cols = _TABLE.reshape(19, 3, 3)
    at_ratio = np.stack([np.interp(lx, x, cols[:, c, j]) for c in coefficients for j in range(3)],
                        axis=-1).reshape(*ratio.shape, len(coefficients), 3)
    # Lagrange quadratic through nu = 0, 0.25, 0.5.
    n0, n1, n2 = TABLE_NU
    w = np.stack(
        [
            (nu - n1) * (nu - n2) / ((n0 - n1) * (n0 - n2)),
            (nu - n0) * (nu - n2) / ((n1 - n0) * (n1 - n2)),
            (nu - n0) * (nu - n1) / ((n2 - n0) * (n2 - n1)),
        ],
        axis=-1,
    )
    return np.einsum("...cn,...n->...c", at_ratio, w)
