"""The compiled per-band reductions (models.corrugation_jit) against their numpy twins
(models.corrugation), which the tests of test_corrugation.py check against closed forms: the same
numbers to the last bits of exp and log, and the same exact edge cases."""

import numpy as np

from rail_monitor.models import corrugation as cg
from rail_monitor.models import corrugation_jit as jit


def _states(seed: int = 11):
    rng = np.random.default_rng(seed)
    x = np.log(rng.uniform(1e-7, 5e-6, (400, 6, 5)))
    g = rng.normal(0, 1e-6, (400, 6, 5)) * rng.integers(0, 2, (400, 6, 1))  # some bands do not grow
    return x, g, np.log(np.array([2e-7, 2e-6, 4e-6, 8e-6, 1.6e-5, 3e-5]))  # the first: all past it


def test_band_log_amplitude_equals_the_numpy_engine():
    x, _, _ = _states()
    # log of a sum of exps: each engine's exp and log differ in the last bit, nothing more.
    np.testing.assert_allclose(jit.band_log_amplitude(x), cg.band_log_amplitude(x), rtol=0, atol=1e-13)


def test_passes_to_band_level_equals_the_numpy_engine_with_its_exact_cases():
    x, g, level = _states()
    want, got = cg.passes_to_band_level(x, g, level), jit.passes_to_band_level(x, g, level)
    # The same zeros (at or past the level) and infinities (nothing grows), bit for bit.
    assert np.array_equal(want == 0.0, got == 0.0) and np.array_equal(np.isinf(want), np.isinf(got))
    assert (want == 0.0).any() and np.isinf(want).any() and (np.isfinite(want) & (want > 0)).any()
    # Roots to the Newton stop (a step of 1e-12 of n) either side.
    np.testing.assert_allclose(got, want, rtol=1e-11)


def test_a_bands_compiled_root_does_not_depend_on_the_bands_solved_with_it():
    x, g, level = _states(5)
    whole = jit.passes_to_band_level(x, g, level)
    one_by_one = np.stack([jit.passes_to_band_level(x[i:i + 1], g[i:i + 1], level)[0] for i in range(len(x))])
    assert np.array_equal(one_by_one, whole)
