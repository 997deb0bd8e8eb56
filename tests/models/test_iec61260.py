"""One-third-octave bands (rail_monitor.models.iec61260) against IEC 61260-1:2014."""

from __future__ import annotations

import numpy as np

from rail_monitor.models import iec61260

CNOSSOS_NOMINAL = [50, 63, 80, 100, 125, 160, 200, 250, 315, 400, 500, 630, 800, 1000, 1250, 1600, 2000, 2500,
                   3150, 4000, 5000, 6300, 8000, 10000]


def test_band_numbers_round_trip_the_nominal_centres_of_iec_61260_annex_e():
    x = iec61260.band_index(CNOSSOS_NOMINAL)
    np.testing.assert_array_equal(x, np.arange(-13, 11))
    np.testing.assert_array_equal(iec61260.nominal_centre(x), CNOSSOS_NOMINAL)
    # Exact centres are within 2 % of the labels (Annex E) and 1/3 octave (base ten) apart.
    np.testing.assert_allclose(iec61260.exact_centre(x), CNOSSOS_NOMINAL, rtol=0.02)
    lo, hi = iec61260.band_edges(x)
    np.testing.assert_allclose(hi / lo, 10 ** 0.1, rtol=1e-12)
    np.testing.assert_allclose(hi[:-1], lo[1:], rtol=1e-12)
