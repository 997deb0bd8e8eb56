"""Porous-ground reflection (models.ground) and its use in the pass-by (models.passby)."""

import numpy as np
import pytest
from scipy.special import erfc

from rail_monitor.models import ground
from rail_monitor.models.passby import Receiver, pass_by

F = np.array([63.0, 250.0, 1000.0, 4000.0])
BAND = np.arange(-13, 11)


def test_the_ground_wave_function_equals_its_erfc_definition():
    """Independent method: F(w) = 1 + i sqrt(pi) w e^(-w^2) erfc(-i w) evaluated with scipy's complex
    erfc, against the Faddeeva form, for |w| up to 3 in the quadrant the ground uses (1e-10)."""
    w = np.array([0.1 + 0.1j, 0.5 + 0.2j, 1.0 + 1.0j, 2.0 + 0.5j, 3.0 + 2.0j])
    direct = 1 + 1j * np.sqrt(np.pi) * w * np.exp(-w**2) * erfc(-1j * w)
    np.testing.assert_allclose(ground.ground_wave_function(w), direct, rtol=1e-10)


def test_a_rigid_ground_reflects_everything_and_a_porous_one_less():
    """Limits: an infinite flow resistivity is a hard plane (|Q| = 1 within 1e-4); grass-covered
    soil (200 kPa s/m2, Embleton et al. 1983) at 7.5 m gives the ground-effect dip, |Q|^2 well under
    1 from 500 Hz to 2 kHz, and nearly full reflection at 63 Hz."""
    hard = ground.spherical_reflection(F, 1e15, 7.9, 0.22)
    np.testing.assert_allclose(np.abs(hard), 1.0, atol=1e-4)
    grass = np.abs(ground.spherical_reflection(np.array([63.0, 500.0, 1000.0, 2000.0]), 2e5, 7.9, 0.22)) ** 2
    assert grass[0] > 0.9
    assert np.all(grass[1:] < 0.5)


def test_at_normal_incidence_far_away_q_is_the_plane_wave_coefficient():
    """Asymptote: for k r2 >> 1 at normal incidence the ground wave vanishes, Q -> (Z - 1) / (Z + 1)."""
    z = ground.delany_bazley_impedance(F, 2e5)
    q = ground.spherical_reflection(F, 2e5, 1.0e4, np.pi / 2)
    np.testing.assert_allclose(q, (z - 1) / (z + 1), rtol=1e-3)


def test_the_pass_by_weighs_the_image_path_per_band():
    """A porous ground lowers the pass-by level by at most the image path's share (3 dB for a hard
    ground's equal paths) and by nothing where |Q|^2 -> 1."""
    lw = np.full((1, len(BAND)), 90.0)
    hard = pass_by(lw, BAND, [100.0], [20.0], Receiver(), time_weighted=False)
    soft = pass_by(lw, BAND, [100.0], [20.0], Receiver(ground_flow_resistivity_pa_s_m2=2e5), time_weighted=False)
    drop = hard.lp_db[0] - soft.lp_db[0]
    assert np.all(drop >= -1e-12) and np.all(drop <= 3.1)
    assert drop[0] < 0.3                              # 50 Hz: nearly hard
    assert drop[BAND == 0][0] > 1.5                   # 1 kHz: the dip
    free = pass_by(lw, BAND, [100.0], [20.0], Receiver(ground_reflection=0.0), time_weighted=False)
    assert np.all(soft.lp_db[0] >= free.lp_db[0] - 1e-12)
    assert soft.lpaeq_tp_dba[0] == pytest.approx(float(hard.lpaeq_tp_dba[0]), abs=3.1)
