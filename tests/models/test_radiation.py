"""Radiation efficiencies (rail_monitor.models.radiation) against their published limits."""

import numpy as np

from rail_monitor.models import radiation


def test_radiation_efficiency_limits():
    """Junger & Feit: sigma_1 -> (pi/2)(ka)^3 (line dipole) and 1; Kinsler et al.: piston (ka)^2/2 and 1."""
    small, big = np.array([1e-3, 1e-2]), np.array([50.0, 200.0])
    np.testing.assert_allclose(radiation.oscillating_cylinder(small), np.pi / 2 * small**3, rtol=1e-3)
    np.testing.assert_allclose(radiation.oscillating_cylinder(big), 1.0, atol=0.02)
    np.testing.assert_allclose(radiation.baffled_piston(small), small**2 / 2, rtol=1e-3)
    np.testing.assert_allclose(radiation.baffled_piston(big), 1.0, atol=0.02)
