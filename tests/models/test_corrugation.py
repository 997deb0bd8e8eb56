"""Corrugation growth kernel: single-mode limits and the full kernel on the UIC60 track.

MODELS.md section 2; seed section 2.1, eqs. 1-2.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from rail_monitor.models import corrugation as cg
from rail_monitor.models import hertz
from rail_monitor.models import track as tr

CASES = [(kc, zeta) for kc in (1e-3, 0.1, 1.0, 10.0, 100.0) for zeta in (0.05, 0.2, 0.5)]


def _numerical_max(kc: float, zeta: float, kb: float = 1.0, exact_log: bool = False) -> float:
    """Maximum over r of K_b Re H (or of ln|1 + K_b H|) by a dense scan refined with Brent."""
    def growth(r):
        h = cg.single_mode_kernel(r, kc, zeta)
        return cg.log_growth_per_pass(kb, h) if exact_log else kb * np.real(h)

    r = np.linspace(1e-3, 3 * np.sqrt(1 + kc), 100_001)
    i = int(np.argmax(growth(r)))
    res = minimize_scalar(lambda x: -growth(x), bracket=(r[i - 1], r[i], r[i + 1]), tol=1e-12)
    return float(-res.fun)


@pytest.mark.parametrize(("kc", "zeta"), CASES)
def test_exact_single_mode_maximum_matches_numerical_maximisation(kc, zeta):
    assert float(cg.single_mode_growth_max(1.0, kc, zeta)) == pytest.approx(_numerical_max(kc, zeta), rel=1e-9)


def test_seed_formula_is_the_small_kc_limit():
    # The resonant part K_c / (4 zeta (1 + zeta)) of the seed's eq. (1) matches the exact
    # maximum to O(K_c) as K_c -> 0, and overestimates it badly for real track (K_c >> 1).
    for zeta in (0.05, 0.2, 0.5):
        for kc in (1e-4, 1e-3, 1e-2):
            seed = float(cg.single_mode_growth_seed(1.0, kc, zeta)) - 1
            exact = float(cg.single_mode_growth_max(1.0, kc, zeta)) - 1
            assert seed / exact - 1 == pytest.approx(0.0, abs=3 * kc)
        seed10 = float(cg.single_mode_growth_seed(1.0, 10.0, zeta)) - 1
        assert seed10 > 2 * (float(cg.single_mode_growth_max(1.0, 10.0, zeta)) - 1)


def test_log_kernel_tends_to_the_linear_one_for_small_kb():
    # ln|1 + K_b H| = K_b Re H + O(K_b^2): with K_b = 1e-5 the maxima agree to 1e-4 relative.
    kb = 1e-5
    for kc, zeta in [(1.0, 0.1), (10.0, 0.2)]:
        log_max = _numerical_max(kc, zeta, kb, exact_log=True)
        assert log_max == pytest.approx(float(cg.single_mode_growth_max(kb, kc, zeta)), rel=1e-4)


def test_wavelength_bands_cover_10_to_1000_mm_in_third_octaves():
    bands = cg.wavelength_bands(0.01, 1.0)
    assert bands[0] == pytest.approx(0.01) and bands[-1] == pytest.approx(1.0)
    np.testing.assert_allclose(np.diff(np.log10(bands)), 0.1)
    assert len(bands) == 21


@pytest.fixture(scope="module")
def uic60_kernel():
    """H(f) of a 600 kg wheel on the bay-averaged UIC60 track at 75 kN (k_c about 1.3e9 N/m)."""
    contact = hertz.contact_ellipse(0.42, 1e6, np.inf, 0.3, hertz.contact_modulus(210e9, 0.28), 75e3)
    kc = float(contact.stiffness)
    f = np.geomspace(5.0, 8000.0, 500)
    h = cg.growth_kernel(kc, tr.bay_averaged_receptance(f, tr.Track()) + tr.wheel_receptance(f, 600.0))

    def kernel_at(freq):
        lf = np.log(np.clip(freq, f[0], f[-1]))
        return np.interp(lf, np.log(f), h.real) + 1j * np.interp(lf, np.log(f), h.imag)

    return kc, kernel_at


def test_contact_stiffness_at_75_kn_is_about_1_3e9(uic60_kernel):
    # MODELS.md section 2: k_c = 1.3e9 N/m at 75 kN.
    assert uic60_kernel[0] == pytest.approx(1.3e9, rel=0.05)


def test_speed_spread_lowers_peak_growth_monotonically(uic60_kernel):
    # Same mean speed (20 m/s), normal spread with coefficient of variation cv: the peak of
    # g over 10-1000 mm falls as cv grows (seed section 2.1, MODELS.md section 2).
    _, kernel_at = uic60_kernel
    lam = np.geomspace(0.01, 1.0, 400)
    peaks = []
    for cv in (0.0, 0.05, 0.1, 0.15, 0.2, 0.25):
        if cv == 0:
            v, w = np.array([20.0]), np.array([1.0])
        else:
            v = np.linspace(20 * (1 - 3 * cv), 20 * (1 + 3 * cv), 301)
            w = np.exp(-0.5 * ((v - 20) / (20 * cv)) ** 2)
            w /= w.sum()
        peaks.append(cg.expected_log_growth(1e-5, kernel_at, lam, v, w).max())
    assert np.all(np.diff(peaks) < 0), peaks
