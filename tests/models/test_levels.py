"""Level arithmetic (rail_monitor.models.levels): energy sums and octave aggregation."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.models import levels


def test_energy_sum_and_octaves():
    assert levels.energy_sum([80.0, 80.0]) == pytest.approx(80.0 + 10 * np.log10(2), abs=1e-12)
    assert levels.energy_sum([80.0, -np.inf]) == pytest.approx(80.0)
    x = np.arange(-13, 11)
    octaves, lv = levels.octave_levels(np.full(24, 70.0), x)
    np.testing.assert_array_equal(octaves, np.arange(-12, 10, 3))       # 63 Hz ... 8 kHz octaves
    np.testing.assert_allclose(lv, 70.0 + 10 * np.log10(3))
    # A-weighted total of a flat spectrum equals the energy sum of the A-weights.
    total = levels.a_weighted_total(np.zeros(24), x)
    assert total == pytest.approx(levels.energy_sum(levels.a_weighted(np.zeros(24), x)))
