"""Frequency weighting A (rail_monitor.models.iec61672) against the table of IEC 61672-1:2013."""

from __future__ import annotations

import numpy as np

from rail_monitor.models import iec61672


def test_a_weighting_matches_iec_61672_table():
    # IEC 61672-1:2013 Table 3 (0.1 dB resolution), which is evaluated at the exact base-ten
    # frequencies 1 kHz x 10^(n/10), n = -15, -10, 0, 6, 10 (nominal 31.5, 100, 1k, 4k, 10k Hz).
    f = 1000.0 * 10.0 ** (np.array([-15, -10, 0, 6, 10]) / 10)
    np.testing.assert_allclose(iec61672.a_weighting_db(f), [-39.4, -19.1, 0.0, 1.0, -2.5], atol=0.051)
