"""The compiled kernels (models.corrugation_jit) against their numpy twins (models.corrugation),
which the tests of test_corrugation.py check against closed forms: the per-band reductions to the
last bits of exp and log with the same exact edge cases; the history's sums (additions only, in
the same order) bit for bit."""

import numpy as np

from rail_monitor.models import corrugation_jit as jit
from rail_monitor.models import corrugation_state as cstate


def _states(seed: int = 11):
    rng = np.random.default_rng(seed)
    x = np.log(rng.uniform(1e-7, 5e-6, (400, 6, 5)))
    g = rng.normal(0, 1e-6, (400, 6, 5)) * rng.integers(0, 2, (400, 6, 1))  # some bands do not grow
    return x, g, np.log(np.array([2e-7, 2e-6, 4e-6, 8e-6, 1.6e-5, 3e-5]))  # the first: all past it


def test_band_log_amplitude_equals_the_numpy_engine():
    x, _, _ = _states()
    # log of a sum of exps: each engine's exp and log differ in the last bit, nothing more.
    np.testing.assert_allclose(jit.band_log_amplitude(x), cstate.band_log_amplitude(x), rtol=0, atol=1e-13)


def test_passes_to_band_level_equals_the_numpy_engine_with_its_exact_cases():
    x, g, level = _states()
    want, got = cstate.passes_to_band_level(x, g, level), jit.passes_to_band_level(x, g, level)
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


def _history(seed: int = 3):
    rng = np.random.default_rng(seed)
    growth = rng.normal(0, 1e-6, (300, 6, 5))
    return (np.log(rng.uniform(1e-7, 5e-6, (6, 5))), rng.normal(0, 1e-4, (6, 5)), rng.normal(0, 1e-4, (4, 6, 5)),
            growth, rng.integers(1, 5, 300))


def test_history_sums_equal_the_numpy_engine_bit_for_bit():
    log0, total, by_state, growth, friction = _history()
    want_state, got_state = by_state.copy(), by_state.copy()
    want, got = cstate.history_sums(log0, total, want_state, growth, friction), \
        jit.history_sums(log0, total, got_state, growth, friction)
    assert all(np.array_equal(w, g) for w, g in zip(want, got, strict=True)) and np.array_equal(want_state, got_state)
    # The sums themselves: ln Z after the last pass and the growth by friction state, to rounding.
    np.testing.assert_allclose(got[0][-1], log0 + growth.sum(axis=0), rtol=1e-12)
    np.testing.assert_allclose(got_state[2] - by_state[2], growth[friction == 3].sum(axis=0), rtol=0, atol=1e-15)


def test_window_growth_equals_the_numpy_engine_bit_for_bit():
    rng = np.random.default_rng(8)
    prefix = np.cumsum(rng.normal(0, 1e-6, (500, 6, 5)), axis=0)
    end = np.arange(200, 500)
    start = end - rng.integers(1, 200, len(end))
    axles = rng.integers(4, 40, len(end)).astype(float)
    want, got = cstate.window_growth(prefix, start, end, axles), jit.window_growth(prefix, start, end, axles)
    assert all(np.array_equal(w, g) for w, g in zip(want, got, strict=True))


def test_add_by_day_equals_the_numpy_engine_with_repeated_days():
    _, _, _, growth, friction = _history(4)
    day = np.sort(np.random.default_rng(4).integers(0, 9, len(growth)))  # many passes a day
    scale = np.random.default_rng(5).uniform(0.5, 2.0, len(growth))
    want, got = np.zeros((9, 4, 6, 5)), np.zeros((9, 4, 6, 5))
    cstate.add_by_day(want, day, friction - 1, growth, scale)
    jit.add_by_day(got, day, friction - 1, growth, scale)
    assert np.array_equal(want, got) and np.abs(got).sum() > 0


def test_table_growth_equals_the_numpy_engine_bit_for_bit():
    rng = np.random.default_rng(9)
    table = rng.normal(0, 1e-6, (3, 4, 2, 30, 6, 5))
    n = 400
    idx = (rng.integers(0, 3, n), rng.integers(0, 4, n), rng.integers(0, 2, n), rng.integers(0, 29, n))
    w, scale = rng.uniform(0, 1, n), rng.integers(2, 40, n).astype(float)
    want, got = cstate.table_growth(table, *idx, w, scale), jit.table_growth(table, *idx, w, scale)
    assert np.array_equal(want, got)
    # at a grid point (w = 0) the table's own row, times the scale
    np.testing.assert_array_equal(jit.table_growth(table, *idx, np.zeros(n), np.ones(n)), table[idx])


def test_the_first_band_to_level_is_the_full_solves_argmin_to_the_bit():
    # Bands that cannot be first are not solved; the chosen band is solved as passes_to_band_level
    # solves it. States at the level, with nothing growing, and with one band clearly first.
    x, g, _ = _states(3)
    x, g, level = x[:, 1:], g[:, 1:], np.log(np.array([2e-5, 3e-5, 2.5e-5, 4e-5, 3e-5]))
    g[:50] = 0.0                      # never
    x[50:60, 2] = np.log(5e-5)        # band 2 past its level: 0
    g[60:100, 4] *= 50.0              # band 4 far ahead of the others
    full = jit.passes_to_band_level(x, g, level)
    band, passes = jit.first_band_to_level(x, g, level)
    want = np.where(np.isinf(full).all(axis=1), -1, np.argmin(full, axis=1))
    assert np.array_equal(band, want) and (band[:50] == -1).all() and (passes[50:60] == 0.0).all()
    assert (band == 4).sum() > 40 and ((band >= 0) & (passes > 0)).sum() > 200
    assert np.array_equal(passes, full[np.arange(len(full)), np.argmin(full, axis=1)])
    twin = cstate.first_band_to_level(x, g, level)
    assert np.array_equal(twin[0], band)
    np.testing.assert_allclose(twin[1], passes, rtol=1e-11)
