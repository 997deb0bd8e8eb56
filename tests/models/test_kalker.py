"""Kalker's linear creep coefficients (rail_monitor.models.kalker; Kalker 1990, Table E.3)."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.models import kalker


def test_kalker_table_nodes_and_properties():
    # Kalker (1990) Table E.3: circle, nu = 0.25: C11 = 4.12, C22 = 3.67, C23 = 1.47.
    c = kalker.creep_coefficients(1.0, 0.25)
    assert (float(c.c11), float(c.c22), float(c.c23)) == pytest.approx((4.12, 3.67, 1.47), abs=1e-12)
    # nu = 0: C11 = C22 for every ellipse (both reduce to the same half-space problem).
    ratios = np.geomspace(0.1, 10, 37)
    c0 = kalker.creep_coefficients(ratios, 0.0)
    np.testing.assert_allclose(c0.c11, c0.c22, rtol=1e-12)
    # C22 grows with a/b and with nu.
    assert np.all(np.diff(kalker.creep_coefficients(ratios, 0.28).c22) > 0)
    assert np.all(np.diff(kalker.creep_coefficients(1.4, np.linspace(0, 0.5, 11)).c22) > 0)
    with pytest.raises(ValueError):
        kalker.creep_coefficients(20.0, 0.28)


def test_the_lateral_coefficient_alone_is_the_tables_c22():
    """lateral_creep_coefficient reads only C22's columns: the same numbers as creep_coefficients' C22
    over the table's range of a/b and nu (exact at its nodes: Kalker 1990, Table E.3)."""
    rng = np.random.default_rng(4)
    ratios, nus = np.exp(rng.uniform(np.log(0.1), np.log(10.0), 500)), rng.uniform(0.0, 0.5, 500)
    np.testing.assert_allclose(kalker.lateral_creep_coefficient(ratios, nus),
                               kalker.creep_coefficients(ratios, nus).c22, rtol=1e-15, atol=0.0)
    assert kalker.lateral_creep_coefficient(1.0, 0.25) == pytest.approx(3.67, abs=1e-12)
