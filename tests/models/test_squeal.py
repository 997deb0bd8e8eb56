"""Wheel squeal: contact mechanics, the closed-form limit cycle against the UQ paper and the ODE.

The UQ paper = Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic
and acoustic phenomena", seminar paper: section 3, Figure 5 (rig parameters), Figures 6-7 (results);
docs/models.md, "Wheel squeal".
"""

from __future__ import annotations

import numpy as np
import pytest

from models.test_hertz import RIG, rig_contact
from rail_monitor.models import squeal, squeal_ode, squeal_radiation


# The UQ paper's Figure 5: the two-disc rig.
def rig_k3(convention: str = "kalker_unit") -> float:
    g_ab_c22 = squeal.kalker_lateral_stiffness(rig_contact(), RIG["e"], RIG["nu"])
    return float(squeal.lateral_creep_stiffness(g_ab_c22, RIG["k1"], convention))


def rig_amplitude(vc, convention: str = "kalker_unit") -> squeal.LimitCycle:
    r = RIG
    return squeal.limit_cycle_amplitude(r["v0"], vc, r["load"], r["c"], r["k1"], r["k2"], rig_k3(convention))


def rig_ode(vc: float) -> squeal_ode.TimeDomainResult:
    r = RIG
    return squeal_ode.simulate_limit_cycle(r["v0"], vc, r["load"], r["m"], r["c"], r["k"], r["k1"], r["k2"], rig_k3())


# --- contact mechanics -------------------------------------------------------------------


# --- the UQ paper's rig ------------------------------------------------------------------------


def test_k3_conventions_for_the_rig():
    # docs/models.md: the literal recipe G a b C22 / mu0 gives about 5.5e5 N; the UQ paper's results need
    # about 1.4e5 N (zeta_c ~ 0.007). kalker_unit (G a b C22) is within 6 % of that.
    assert rig_k3("kalker_peak") == pytest.approx(5.5e5, rel=0.02)
    assert rig_k3("kalker_unit") == pytest.approx(1.4e5, rel=0.06)
    assert RIG["load"] / rig_k3("kalker_unit") == pytest.approx(0.007, rel=0.05)


def test_rig_closed_form_reproduces_the_paper():
    # The UQ paper's section 3.3: analytical A w = 0.33 m/s at Vc = 0.39 m/s (tolerance 3 %); a 34 % cut of
    # Vc halves A w (tolerance 5 %).
    lc = rig_amplitude(np.array([0.39, 0.39 * (1 - 0.34)]))
    assert np.all(lc.regime == squeal.REGIME_LIMIT_CYCLE)
    assert lc.amplitude[0] == pytest.approx(0.33, rel=0.03)
    assert lc.amplitude[1] / lc.amplitude[0] == pytest.approx(0.5, rel=0.05)
    # "close to but under the crabbing velocity"
    assert lc.amplitude[0] < 0.39


def test_rig_literal_k3_does_not_reproduce_the_paper():
    # The literal reading pushes the closed form past its no-reverse-slip limit at Vc = 0.39.
    lc = rig_amplitude(0.39, "kalker_peak")
    assert int(lc.regime) == squeal.REGIME_REVERSE_SLIP


def test_rig_squeal_fades_toward_the_onset():
    # The UQ paper's Figure 7a: the squeal trend holds above about 0.15 m/s; below, no squeal. With
    # kalker_unit the onset Vc = u_s = 0.12 m/s: the amplitude at 0.15 m/s is already small
    # and falls to zero (stable) at 0.10 m/s.
    lc = rig_amplitude(np.array([0.10, 0.15, 0.39]))
    assert lc.regime[0] == squeal.REGIME_STABLE and lc.amplitude[0] == 0.0
    assert 0.0 < lc.amplitude[1] < 0.15 * lc.amplitude[2]
    assert float(lc.critical_slip[0]) == pytest.approx(0.12, abs=0.01)
    # steep rise: d(A w)/d(Vc) = 1 / cos(phi) > 1 everywhere in the limit-cycle regime
    vc = np.linspace(0.13, 0.5, 50)
    assert np.all(np.diff(rig_amplitude(vc).amplitude) / np.diff(vc) > 1.0)


def test_rig_time_domain_matches_the_paper_and_closed_form():
    # The UQ paper's Figure 6a: simulation settles near 0.35 m/s (10 %); the ODE with the same
    # piecewise-linear curve agrees with the closed form within 1 %.
    ode = rig_ode(0.39)
    assert ode.settled
    assert ode.amplitude == pytest.approx(0.35, rel=0.10)
    assert ode.amplitude == pytest.approx(float(rig_amplitude(0.39).amplitude), rel=0.01)


def test_spl_trend_follows_20_lg_amplitude():
    # The UQ paper's section 3.3: sound power ~ velocity squared, so the level change is 20 lg of the
    # amplitude ratio: halving A w (the 34 % cut) lowers the level by 6.0 dB (0.5 dB).
    lc = rig_amplitude(np.array([0.39, 0.39 * 0.66]))
    rel = squeal_radiation.relative_level(lc.amplitude, lc.amplitude[0])
    lev = squeal_radiation.radiated_level(lc.amplitude, 1143.0, distance=0.05)
    assert rel[1] == pytest.approx(-6.0, abs=0.5)
    assert lev.level_db[1] - lev.level_db[0] == pytest.approx(rel[1], abs=1e-9)


# --- the general solver --------------------------------------------------------------------


def test_phase_solves_the_energy_balance_equation():
    # The returned half adhesion angle satisfies sin 2phi - 2phi = 2 pi (c + s2) / (s1 - s2)
    # (module docstring) to round-off, from just past the onset to the edge of existence.
    k3, v0, w = rig_k3(), RIG["v0"], RIG["load"]
    k2 = -np.geomspace(1e-4, 0.25, 400)
    lc = squeal.limit_cycle_amplitude(v0, 0.3, w, 0.0, RIG["k1"], k2, k3)
    ok = ~np.isnan(lc.phi)
    assert ok.sum() > 300
    s1, s2 = RIG["k1"] * k3 / v0, k2 * k3 / v0
    rhs = 2 * np.pi * s2 / (s1 - s2)
    np.testing.assert_allclose(np.sin(2 * lc.phi[ok]) - 2 * lc.phi[ok], rhs[ok], rtol=1e-9, atol=1e-15)

# A 2^(4-1) fractional factorial over speed, Vc / u_s, damping and falling slope, on the rig's
# wheel mode and k3; every case keeps mu > 0 over its cycle and no reverse slip.
GRID = [
    (v0, ratio, c, k2)
    for i, v0 in enumerate((10.0, 25.0))
    for j, ratio in enumerate((1.5, 3.0))
    for n, c in enumerate((10.0, 42.0))
    for k2 in ((-0.01, -0.03)[i ^ j ^ n],)
]


@pytest.mark.parametrize(("v0", "ratio", "c", "k2"), GRID)
def test_closed_form_agrees_with_the_ode_across_a_grid(v0, ratio, c, k2):
    k3 = rig_k3()
    vc = ratio * squeal.critical_slip_velocity(v0, RIG["load"], k3)
    lc = squeal.limit_cycle_amplitude(v0, vc, RIG["load"], c, RIG["k1"], k2, k3)
    assert int(lc.regime) == squeal.REGIME_LIMIT_CYCLE and bool(lc.friction_positive)
    ode = squeal_ode.simulate_limit_cycle(v0, float(vc), RIG["load"], RIG["m"], c, RIG["k"], RIG["k1"], k2, k3)
    assert ode.settled
    assert ode.amplitude == pytest.approx(float(lc.amplitude), rel=0.01)


@pytest.mark.parametrize(("ratio", "regime"),
                         [(30.0, squeal.REGIME_LIMIT_CYCLE), (40.0, squeal.REGIME_REVERSE_SLIP)])
def test_regime_flag_on_both_sides_of_the_validity_limit(ratio, regime):
    # A mildly falling curve (k2 = -0.0027) with light damping reaches the no-reverse-slip
    # limit A w = Vc + u_s near Vc = 35 u_s while mu stays positive. The flag must say whether
    # the time-domain solution reverses slip (Vc + y' < -u_s); on both sides the amplitude is
    # within 2 % of the ODE's.
    k3, c, k2 = rig_k3(), 5.0, -0.0027
    u_s = float(squeal.critical_slip_velocity(RIG["v0"], RIG["load"], k3))
    vc = ratio * u_s
    lc = squeal.limit_cycle_amplitude(RIG["v0"], vc, RIG["load"], c, RIG["k1"], k2, k3)
    assert int(lc.regime) == regime and bool(lc.friction_positive)
    ode = squeal_ode.simulate_limit_cycle(RIG["v0"], vc, RIG["load"], RIG["m"], c, RIG["k"], RIG["k1"], k2, k3)
    reverse_slip = float(np.min(vc + ode.velocity)) < -u_s
    assert reverse_slip == (regime == squeal.REGIME_REVERSE_SLIP)
    assert ode.amplitude == pytest.approx(float(lc.amplitude), rel=0.02 if reverse_slip else 0.01)


@pytest.mark.parametrize(("k3", "vc", "k2", "c"), [
    (3.5e5, 0.39, -0.02, 42.0),    # the rig's mode with a stiffer contact: just past the closed form's limit
    (4.0e5, 0.39, -0.02, 42.0),    # reverse slip and the zero-friction floor
    (6.0e5, 0.39, -0.02, 42.0),
    (2.5e5, 0.30, -0.05, 42.0),    # steeply falling: the floor is reached within the cycle
    (2.5e5, 0.30, -0.05, 400.0),   # ... with ten times the damping
    (3.5e5, 0.50, -0.02, 42.0),
    (5.0e5, 0.15, -0.05, 42.0),
    (5.0e5, 0.50, -0.01, 42.0),
])
def test_amplitude_past_the_closed_form_matches_direct_integration(k3, vc, k2, c):
    # Independent method: the ODE integrated in time (DOP853, no events) on the rig's mode
    # (m = 3.1 kg, k = 1.6e8 N/m, W = 1000 N, V0 = 17.8 m/s). Where the cycle reaches reverse slip
    # or zero friction, the energy balance over the whole curve is within 2 % of it; the closed
    # form there was 7-25 % off (and the old stick-slip bound Vc 7-15 % low).
    lc = squeal.limit_cycle_amplitude(RIG["v0"], vc, RIG["load"], c, RIG["k1"], k2, k3)
    assert int(lc.regime) == squeal.REGIME_REVERSE_SLIP
    ode = squeal_ode.simulate_limit_cycle(RIG["v0"], vc, RIG["load"], RIG["m"], c, RIG["k"], RIG["k1"], k2, k3)
    assert ode.settled
    assert float(lc.amplitude) == pytest.approx(ode.amplitude, rel=0.02)


@pytest.mark.parametrize(
    ("what", "vc", "c", "k2"),
    [("positive k2 (friction modifier)", 0.39, 42.0, 0.01), ("Vc below critical slip", 0.10, 42.0, -0.02),
     ("damping beats the falling slope", 0.39, 400.0, -0.02)],
)
def test_stable_cases_give_no_squeal(what, vc, c, k2):
    k3 = rig_k3()
    lc = squeal.limit_cycle_amplitude(RIG["v0"], vc, RIG["load"], c, RIG["k1"], k2, k3)
    assert int(lc.regime) == squeal.REGIME_STABLE and float(lc.amplitude) == 0.0, what
    # the ODE started with a 0.05 m/s disturbance decays
    ode = squeal_ode.simulate_limit_cycle(RIG["v0"], vc, RIG["load"], RIG["m"], c, RIG["k"], RIG["k1"], k2, k3,
                                      initial_velocity=0.05, max_cycles=1000)
    assert ode.amplitude < 1e-3, what


# --- acoustics ------------------------------------------------------------------------------


def test_radiated_power_is_conserved_over_the_hemisphere():
    # Conservation: the intensity p^2 / (rho0 c0) at r times the hemisphere 2 pi r^2 is the
    # source power rho0 c0 sigma S <v^2>.
    amp, r = 0.2, np.array([1.0, 7.5, 30.0])
    lev = squeal_radiation.radiated_level(amp, 1000.0, radiating_area=0.9, radiation_efficiency=1.0,
                                          spatial_average=0.5, distance=r)
    p2 = (20e-6) ** 2 * 10 ** (lev.level_db / 10)
    power = squeal_radiation.RHO0_C0 * 1.0 * 0.9 * 0.5 * amp**2 / 2
    np.testing.assert_allclose(p2 / squeal_radiation.RHO0_C0 * 2 * np.pi * r**2, power, rtol=1e-9)
