"""Grinding cycles under exponential growth (economics.cycles) against the same law stepped pass by
pass: multiply by exp(g) each axle pass, grind back on reaching the threshold."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.economics.cycles import sawtooth


def test_the_sawtooth_is_the_law_stepped_pass_by_pass():
    post, threshold, g = 2e-6, 2e-6 * np.exp(1.0), 0.0123       # a cycle of 81.3 axle passes
    n = np.arange(1000)
    z, grinds = sawtooth(post, threshold, g, n)
    stepped, count, made = post, 0, []
    for _ in n:
        made.append((stepped, count))
        stepped *= np.exp(g)
        if stepped >= threshold * (1 - 1e-12):
            stepped, count = stepped / (threshold / post), count + 1   # ground back by the threshold's ratio
    np.testing.assert_allclose(z, [m[0] for m in made], rtol=1e-9)
    np.testing.assert_array_equal(grinds, [m[1] for m in made])
    assert grinds[-1] == int(999 * g)                                # ln(threshold/post) = 1
    assert z.max() < threshold and z.min() >= post * (1 - 1e-12)


def test_slower_growth_grinds_in_proportion():
    """Growth cut by a factor F lengthens the cycle by F: over a span of many cycles the grinds fall
    by F to within one grind (the paper's cost cut: 1 - 1/F)."""
    n = np.linspace(0, 1e6, 5001)
    _, now = sawtooth(1e-6, 1e-5, 2.3e-4, n)
    _, advised = sawtooth(1e-6, 1e-5, 2.3e-4 / 1.7, n)
    assert now[-1] / advised[-1] == pytest.approx(1.7, rel=0.02)
    assert sawtooth(1e-6, 1e-5, 0.0, n)[1].max() == 0
