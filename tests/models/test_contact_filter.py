"""The Hertzian line contact filter (rail_monitor.models.contact_filter) against a direct average
over the patch."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from rail_monitor.models.contact_filter import hertzian_line_filter


def test_contact_filter_matches_a_direct_average_over_the_hertzian_patch():
    # Independent method: the Hertz-weighted average of cos(k x) over -a..a by quadrature.
    a = 0.006
    for lam in (0.005, 0.01, 0.02, 0.05, 0.2):
        k = 2 * np.pi / lam
        num = quad(lambda x, k=k: np.sqrt(1 - (x / a) ** 2) * np.cos(k * x), -a, a, limit=200)[0]
        den = np.pi * a / 2
        assert float(hertzian_line_filter(lam, a)) == pytest.approx(num / den, abs=1e-9)
    # Long waves pass; the first zero is at k a = 3.8317 (first zero of J1).
    assert float(hertzian_line_filter(10.0, a)) == pytest.approx(1.0, abs=1e-5)
    assert float(hertzian_line_filter(2 * np.pi * a / 3.831706, a)) == pytest.approx(0.0, abs=1e-6)
