"""Elliptical Hertz contact (rail_monitor.models.hertz): the UQ paper's rig, the sphere limit, the contact
stiffness."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.models import hertz

RIG = {"e": 175e9, "nu": 0.28, "load": 1000.0, "m": 3.1, "c": 42.0, "k": 1.6e8, "v0": 17.8, "k1": 0.27, "k2": -0.02}


RIG_RADII = (0.213, 0.300, 0.085, 0.040)  # lower wheel rolling/transverse, upper wheel rolling/transverse [m]


def rig_contact() -> hertz.HertzContact:
    return hertz.contact_ellipse(*RIG_RADII, hertz.contact_modulus(RIG["e"], RIG["nu"]), RIG["load"])


def test_hertz_rig_semi_axes_match_the_paper():
    # docs/models.md: Hertz gives a = 0.853 mm, b = 0.595 mm for the rig (3 significant figures).
    c = rig_contact()
    assert float(c.a) == pytest.approx(0.853e-3, rel=1e-3)
    assert float(c.b) == pytest.approx(0.595e-3, rel=2e-3)


def test_hertz_sphere_limit_is_the_circular_solution():
    # Johnson (1985) eqs. 4.22-4.23: sphere on a flat, a^3 = 3 P R / (4 E*), delta = a^2 / R.
    e_star = hertz.contact_modulus(210e9, 0.3)
    load, radius = np.array([1e3, 5e4, 1e5]), 0.46
    c = hertz.contact_ellipse(radius, radius, np.inf, np.inf, e_star, load)
    a_ref = np.cbrt(3 * load * radius / (4 * e_star))
    np.testing.assert_allclose(c.a, a_ref, rtol=1e-9)
    np.testing.assert_allclose(c.b, a_ref, rtol=1e-9)
    np.testing.assert_allclose(c.approach, a_ref**2 / radius, rtol=1e-9)


def test_hertz_stiffness_is_the_derivative_of_load_against_approach():
    # Independent method: central finite difference of P(delta) against the closed 3P/(2 delta).
    e_star = hertz.contact_modulus(210e9, 0.28)
    load = 65e3 * np.array([1 - 1e-4, 1, 1 + 1e-4])
    c = hertz.contact_ellipse(0.42, 1e6, np.inf, 0.3, e_star, load)
    slope = (load[2] - load[0]) / (c.approach[2] - c.approach[0])
    assert slope == pytest.approx(float(c.stiffness[1]), rel=1e-6)
    # and a wheel on a rail is an ellipse elongated along the rail (a > b) with a mean pressure p0 * 2/3
    assert c.a[1] > c.b[1]
    assert load[1] / (np.pi * c.a[1] * c.b[1]) == pytest.approx(2 / 3 * c.p0[1], rel=1e-12)


@pytest.mark.parametrize("ratio", [1.05, 1.5, 3.0, 10.0, 1e3, 1e8])
def test_hertz_axis_ratio_is_the_root_to_1e_12(ratio):
    # Johnson (1985) eq. 4.37 fixes k from B/A; the solved k brackets the root within 1e-12 (its
    # own equation evaluated on either side), and k falls as B/A grows (the bisection's premise).
    k = hertz._axis_ratio(ratio)
    above, below = (hertz._ratio_for_axis_ratio(k * (1.0 + s)) for s in (-1e-12, 1e-12))
    assert above >= ratio * (1.0 - 1e-12) and below <= ratio * (1.0 + 1e-12)
    assert hertz._axis_ratio(ratio * 1.01) < k < 1.0
