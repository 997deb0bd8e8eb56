"""The contact state of a pass (rail_monitor.core.contact): k3 under each convention, the
saturation creepage per friction state and the regime."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rail_monitor.core.contact import REGIME_FULL_SLIDING, contact_state
from rail_monitor.core.passes import FRICTION_NAMES, PassTable, with_class_defaults
from rail_monitor.models import hertz, squeal
from rail_monitor.whatif.squeal import RIG, RIG_RADII_M


def _passes(site, aoa_mrad, friction, cls="emu", load=0.0, speed=19.0) -> PassTable:
    aoa = np.atleast_1d(np.asarray(aoa_mrad, float))
    n = len(aoa)
    return with_class_defaults(PassTable(
        stamp_ns=1_790_000_000_000_000_000 + np.arange(n, dtype=np.int64), train_id=[f"T{i}" for i in range(n)],
        vehicle_class=[cls] * n, vehicle_count=[4] * n, axle_count=[0] * n, speed_mps=np.full(n, speed),
        angle_of_attack_rad=1e-3 * aoa, wheel_load_n=np.full(n, load), friction_state=np.broadcast_to(friction, n),
        train_length_m=[0.0] * n), site)


def test_reduced_kalker_keeps_the_rig_and_is_calibrated_on_it():
    # The UQ paper's rig (its Figure 5; k1 = 0.27): with k_A = the rig's k1, reduced_kalker gives
    # exactly the k3 = G a b C22 that reproduces its Figures 6-7 (tests/models/test_squeal.py).
    e, nu = RIG["young_modulus_pa"], RIG["poisson_ratio"]
    patch = hertz.contact_ellipse(*RIG_RADII_M, hertz.contact_modulus(e, nu), RIG["load_n"])
    kalker = squeal.kalker_lateral_stiffness(patch, e, nu)
    reduced = squeal.lateral_creep_stiffness(kalker, RIG["k1"], "reduced_kalker")
    assert reduced == pytest.approx(float(kalker), rel=1e-12)
    assert squeal.lateral_creep_stiffness(kalker, RIG["k1"], "kalker_peak") == pytest.approx(reduced / 0.27)


def test_the_saturation_creepage_of_each_state_is_proportional_to_its_friction_peak(site):
    # zeta_c = W / k3 = mu0 W / (k_A G a b C22): Kalker's slope does not depend on friction, the
    # Coulomb limit does (docs/models.md, "The contact state of a pass").
    loads = np.linspace(40e3, 110e3, 8)
    ratios = []
    for code in FRICTION_NAMES:
        table = _passes(site, np.full(8, 5.0), code)
        table.wheel_load_n = loads
        cs = contact_state(site, table)
        ratios.append(cs.saturation_creepage / cs.k1)
    for r in ratios[1:]:
        np.testing.assert_allclose(r, ratios[0], rtol=1e-12)
    # Under kalker_unit (version 0.2's default) the onset does not move with friction at all.
    unit = dataclasses.replace(site, contact=dataclasses.replace(site.contact, k3_convention="kalker_unit"))
    onsets = [contact_state(unit, _passes(unit, 5.0, code)).saturation_creepage[0] for code in FRICTION_NAMES]
    assert np.ptp(onsets) == pytest.approx(0.0, abs=1e-15)


def test_the_regime_is_full_sliding_beyond_saturation_and_every_squeal_slides(site, site_values):
    from rail_monitor.squeal.config import squeal_config
    from rail_monitor.squeal.predict import predict

    table = _passes(site, np.linspace(0.0, 30.0, 301), 1)
    cs = contact_state(site, table)
    np.testing.assert_array_equal(cs.regime == REGIME_FULL_SLIDING, cs.creepage > cs.saturation_creepage)
    assert 0 < np.mean(cs.full_sliding) < 1
    np.testing.assert_allclose(cs.crabbing_mps, 19.0 * np.sin(1e-3 * np.linspace(0.0, 30.0, 301)), rtol=1e-12)
    # The squeal model's instability needs Vc > u_s: a squealing pass is always a sliding one.
    unstable = predict(squeal_config(site_values), site, table)["unstable"]
    assert unstable.any() and not np.any(unstable & ~cs.full_sliding)
