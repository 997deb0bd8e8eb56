"""Pass-by of moving point sources per axle (models.passby_axles) against independent methods:
quadrature of the point-source kernel, a time integration of the F weighting on the history summed
over every axle, the slow single-source limit, and the line source it must converge to."""

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from rail_monitor.models import axle_layout, levels, passby, passby_axles, passby_axles_peak, passby_kernel

RECEIVER = passby.Receiver(7.5, 1.2, 0.5, 0.0, 1.0)
(R1, _), (R2, _) = RECEIVER.paths()
D = RECEIVER.distance_m


def _layout(length, vehicles, axles, ratio=16.0 / 23.0, semi=1.25):
    return axle_layout.axle_layout([length], [vehicles], [axles], ratio, semi)


def test_axle_layout_puts_bogies_about_the_vehicle_middle():
    np.testing.assert_allclose(_layout(23.0, 1, 4).offsets_m[0], [2.25, 4.75, 18.25, 20.75], atol=1e-12)
    np.testing.assert_allclose(_layout(23.0, 1, 6).offsets_m[0], [2.25, 3.5, 4.75, 18.25, 19.5, 20.75], atol=1e-12)
    np.testing.assert_allclose(_layout(15.0, 1, 2, 0.6, 1.0).offsets_m[0], [3.0, 12.0], atol=1e-12)   # at the pivots
    np.testing.assert_allclose(_layout(12.0, 1, 3).offsets_m[0], [2.0, 6.0, 10.0], atol=1e-12)          # odd: evenly
    mixed = axle_layout.axle_layout([46.0, 30.0], [2, 3], [8, 6], 0.7, 1.0)
    assert mixed.offsets_m.shape == (2, 4) and list(mixed.axles_per_vehicle) == [4.0, 2.0]
    assert np.isnan(mixed.offsets_m[1, 2:]).all()


def _all_axle_history(layout, length, speed, t):
    """The squared pressure of every axle, summed directly (no near/far split), per unit c1 = c2 = 1."""
    m = np.arange(layout.vehicles[0])
    s = (m[:, None] * layout.pitch_m[0] + layout.offsets_m[0][None, :]).ravel()
    x = 0.5 * length + speed * np.asarray(t, float)[..., None] - s          # front at L/2 + v t
    w = layout.pitch_m[0] / layout.axles_per_vehicle[0]
    return w * (passby_kernel.point_kernel(x, D, R1) + passby_kernel.point_kernel(x, D, R2)).sum(axis=-1)


@pytest.mark.parametrize("vehicles, speed", [(1, 22.2), (6, 22.2), (30, 14.0)])
def test_window_kernel_matches_quadrature(vehicles, speed):
    length = 23.0 * vehicles
    layout = _layout(length, vehicles, 4 * vehicles)
    tp = length / speed
    want, _ = quad(lambda t: float(_all_axle_history(layout, length, speed, t - 0.5 * tp)), 0.0, tp,
                   limit=2000, epsabs=1e-15, epsrel=1e-11)
    got = passby_axles.window_kernel(layout, [length], D, R1) + passby_axles.window_kernel(layout, [length], D, R2)
    assert got[0] == pytest.approx(want / tp, rel=1e-8)


@pytest.mark.parametrize("vehicles, speed", [(2, 22.2), (6, 22.2), (30, 14.0)])
def test_f_weighted_peak_matches_a_time_integration_over_every_axle(vehicles, speed):
    """LpAFmax against solve_ivp of tau dy/dt = x - y on the history of all axles (the 30-wagon
    train exercises the far vehicles taken as line segments), 0.02 dB."""
    length = 23.0 * vehicles
    layout = _layout(length, vehicles, 4 * vehicles)
    tau = passby_kernel.F_TIME_CONSTANT_S
    span = (-(0.5 * length + 200.0) / speed, (0.5 * length + 200.0) / speed)
    sol = solve_ivp(lambda t, y: (_all_axle_history(layout, length, speed, t) - y) / tau, span, [0.0],
                    max_step=0.002, rtol=1e-9, atol=1e-16)
    got = passby_axles_peak.f_weighted_peak([(np.ones(1), R1), (np.ones(1), R2)], layout, [length], [speed], D)
    assert 10 * np.log10(got[0]) == pytest.approx(10 * np.log10(sol.y[0].max()), abs=0.02)


def test_a_slow_single_axle_peaks_at_its_closest_approach():
    """One axle passing slowly (v tau << d): the F-weighted peak is the squared pressure at x = 0,
    W (g_direct(0) + g_image(0)), within 0.01 dB."""
    layout = axle_layout.axle_layout([4.0], [1], [1], 0.0, 0.0)
    got = passby_axles_peak.f_weighted_peak([(np.ones(1), R1), (np.ones(1), R2)], layout, [4.0], [0.5], D)
    want = 4.0 * (passby_kernel.point_kernel(0.0, D, R1) + passby_kernel.point_kernel(0.0, D, R2))
    assert 10 * np.log10(got[0]) == pytest.approx(10 * np.log10(want), abs=0.01)


def test_axles_keep_the_exposure_and_approach_the_line_source_when_long():
    band = np.array([0])
    lw = np.array([[90.0]]) - levels.a_weighted(0.0, band)
    for vehicles in (3, 40):
        length = 23.0 * vehicles
        layout = _layout(length, vehicles, 4 * vehicles)
        line = passby.pass_by(lw, band, [length], [22.2], RECEIVER)
        axles = passby.pass_by(lw, band, [length], [22.2], RECEIVER,
                               geometry=passby.pass_geometry(band, [length], [22.2], RECEIVER, layout))
        assert axles.tel_dba[0] == pytest.approx(line.tel_dba[0], abs=1e-9)        # the same exposure
        assert abs(axles.lpaeq_tp_dba[0] - line.lpaeq_tp_dba[0]) < (0.2 if vehicles == 3 else 0.01)
        # Each bogie passes as a peak that the F weighting partly follows: LpAFmax above the line's.
        assert 0.5 < axles.lpafmax_dba[0] - line.lpafmax_dba[0] < 2.0


def test_extreme_but_valid_trains_cost_bounded_memory_and_give_finite_levels():
    """The pass table admits trains no timetable runs (one 5 km vehicle of 2,000 axles at walking
    pace, 500 vehicles in 50 m, 500 at 120 m/s): the history's blocks stay small and every level is finite."""
    import tracemalloc

    length, vehicles, axles, speed = [5000.0, 50.0, 5000.0], [1, 500, 500], [2000, 2000, 2000], [1.0, 1.0, 120.0]
    layout = axle_layout.axle_layout(length, vehicles, axles, 0.7, 1.0)
    assert layout.offsets_m.shape[1] == axle_layout.MAX_AXLES_PER_VEHICLE
    tracemalloc.start()
    peak = passby_axles_peak.f_weighted_peak([(np.ones(3), R1), (np.ones(3), R2)], layout, length, speed, D)
    mean = passby_axles.window_kernel(layout, length, D, R1)
    _, most = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert np.all(np.isfinite(peak)) and np.all(peak > 0) and np.all(np.isfinite(mean))
    assert most < 400e6


@pytest.mark.parametrize("axles", [True, False])
def test_a_second_source_line_adds_its_energy_and_shares_the_time_history(axles):
    """CNOSSOS-EU's source B (4 m) beside source A: LpAeq,Tp and TEL are the energy sums of the two lines
    computed apart (exact: both are exposures over the same Tp), LpAFmax lies between the louder line's and
    the energy sum of the two (the F weighting follows their summed history). Two lines at one height are one
    line of their summed power (the history is linear in the paths' powers), 1e-9 dB."""
    band = np.arange(-6, 9)
    length, vehicles, speed = 92.0, 4, [22.2]
    layout = _layout(length, vehicles, 16) if axles else None
    high = passby.Receiver(7.5, 1.2, 4.0, 0.0, 1.0)

    def geometry(receiver):
        return passby.pass_geometry(band, [length], speed, receiver, layout)

    ga, gb = geometry(RECEIVER), geometry(high)
    rng = np.random.default_rng(5)
    lw_a, lw_b = 80.0 + 10.0 * rng.random((1, len(band))), 75.0 + 10.0 * rng.random((1, len(band)))
    a_alone = passby.pass_by(lw_a, band, [length], speed, RECEIVER, geometry=ga)
    b_alone = passby.pass_by(lw_b, band, [length], speed, high, geometry=gb)
    both = passby.pass_by(lw_a, band, [length], speed, RECEIVER, geometry=ga, elevated=(lw_b, gb))

    def energy(x, y):
        return levels.level(levels.power(x) + levels.power(y))

    np.testing.assert_allclose(both.lp_db, energy(a_alone.lp_db, b_alone.lp_db), rtol=0, atol=1e-9)
    assert both.lpaeq_tp_dba[0] == pytest.approx(energy(a_alone.lpaeq_tp_dba, b_alone.lpaeq_tp_dba)[0], abs=1e-9)
    assert both.tel_dba[0] == pytest.approx(energy(a_alone.tel_dba, b_alone.tel_dba)[0], abs=1e-9)
    peak = both.lpafmax_dba[0]
    assert max(a_alone.lpafmax_dba[0], b_alone.lpafmax_dba[0]) < peak
    assert peak < energy(a_alone.lpafmax_dba, b_alone.lpafmax_dba)[0] + 1e-9
    summed = passby.pass_by(energy(lw_a, lw_b), band, [length], speed, RECEIVER, geometry=ga)
    same_height = passby.pass_by(lw_a, band, [length], speed, RECEIVER, geometry=ga, elevated=(lw_b, ga))
    assert same_height.lpafmax_dba[0] == pytest.approx(summed.lpafmax_dba[0], abs=1e-9)
    np.testing.assert_allclose(same_height.lp_db, summed.lp_db, rtol=0, atol=1e-9)
    # No power on the second line: the first line's levels, bit for bit.
    silent = passby.pass_by(lw_a, band, [length], speed, RECEIVER, geometry=ga,
                            elevated=(np.full_like(lw_b, -np.inf), gb))
    np.testing.assert_array_equal(silent.lp_db, a_alone.lp_db)


def _mixed_trains(n: int, seed: int = 3):
    """n trains of 1-30 vehicles (short ones summed axle by axle whole, long ones with far segments)."""
    rng = np.random.default_rng(seed)
    vehicles = rng.integers(1, 31, n)
    length = vehicles * rng.uniform(10.0, 26.0, n)
    layout = axle_layout.axle_layout(length, vehicles, vehicles * rng.choice([2, 3, 4, 6], n), 0.7, 1.25)
    return layout, length, rng.uniform(5.0, 45.0, n), rng


def test_the_compiled_engine_gives_the_numpy_engines_peaks():
    # models.passby_axles_jit is the numpy engine's arithmetic fused: the same bits where no far
    # segment's arctangent enters, to 1e-13 elsewhere; two sets of paths share one history.
    layout, length, speed, rng = _mixed_trains(300)
    r3 = float(np.hypot(D, 2.8))
    paths = [[(rng.uniform(0.5, 2.0, 300), R1), (rng.uniform(0.5, 2.0, 300), R2)],
             [(rng.uniform(0.5, 2.0, 300), R1), (rng.uniform(0.5, 2.0, 300), R2), (rng.uniform(0, 1, 300), r3)]]
    want = passby_axles_peak.f_weighted_peaks(paths, layout, length, speed, D, "numpy")
    got = passby_axles_peak.f_weighted_peaks(paths, layout, length, speed, D, "numba")
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=0.0)
    whole = layout.vehicles <= 4   # within the near zone whatever the speed: no arctangent
    assert whole.any() and np.array_equal(got[:, whole], want[:, whole])
    for m, p in enumerate(paths):  # a set alone, on the joint window (the largest path distance)
        alone = passby_axles_peak.f_weighted_peak(p, layout, length, speed, D, "numba", window_r=r3)
        np.testing.assert_array_equal(alone, got[m])


def test_a_pass_gets_the_same_peak_alone_as_in_a_batch_with_either_engine():
    layout, length, speed, rng = _mixed_trains(40, 8)
    paths = [(rng.uniform(0.5, 2.0, 40), R1), (rng.uniform(0.5, 2.0, 40), R2)]
    for engine in ("numpy", "numba"):
        batch = passby_axles_peak.f_weighted_peak(paths, layout, length, speed, D, engine)
        for i in (0, 17, 39):
            one = layout.take(np.array([i]))
            alone = passby_axles_peak.f_weighted_peak([(c[i:i + 1], r) for c, r in paths], one, length[i:i + 1],
                                                 speed[i:i + 1], D, engine)
            assert alone[0] == batch[i], engine


@pytest.mark.parametrize("elements", [1, 5_000, 32_000, 10**7])
def test_the_numpy_blocks_change_no_bit(monkeypatch, elements):
    # HISTORY_ELEMENTS sizes the blocks for the cache only: passes are elementwise and the axles
    # summed one at a time in a fixed order, so any block size gives the same bits.
    layout, length, speed, rng = _mixed_trains(120, 8)
    paths = [(rng.uniform(0.5, 2.0, 120), R1), (rng.uniform(0.5, 2.0, 120), R2)]
    want = (passby_axles_peak.f_weighted_peak(paths, layout, length, speed, D),
            passby_axles.window_kernels(layout, length, D, [R1, R2]))
    for module in (passby_axles, passby_axles_peak):  # each sizes its own blocks by it
        monkeypatch.setattr(module, "HISTORY_ELEMENTS", elements)
    got = (passby_axles_peak.f_weighted_peak(paths, layout, length, speed, D),
           passby_axles.window_kernels(layout, length, D, [R1, R2]))
    for w, g in zip(want, got, strict=True):
        np.testing.assert_array_equal(g, w)


def test_the_compiled_window_kernel_gives_the_numpy_engines():
    # LpAeq,Tp's exact sum over every axle: equal but for the arctangent's last bit.
    layout, length, _, _ = _mixed_trains(200, 4)
    want = passby_axles.window_kernels(layout, length, D, [R1, R2], "numpy")
    got = passby_axles.window_kernels(layout, length, D, [R1, R2], "numba")
    np.testing.assert_allclose(got, want, rtol=1e-13, atol=0.0)
    np.testing.assert_array_equal(want[1], passby_axles.window_kernel(layout, length, D, R2))


def test_near_axle_terms_over_a_common_denominator_are_the_direct_quotients():
    # One division per pair of path distances against the direct directivity / (x^2 + R^2) of
    # each: the same numbers to a few ulps, for a pair and for an odd last radius.
    from rail_monitor.models.passby_kernel import BROADSIDE, OMNI

    x2 = np.random.default_rng(6).uniform(0.0, 1e5, 2000) ** 2 / 1e3
    r2 = [R1 * R1, R2 * R2, float(np.hypot(D, 2.8)) ** 2]
    broad = BROADSIDE * D * D
    direct = (broad / (x2 + D * D) + OMNI)
    for got, rk in zip(passby_axles_peak.near_axle_terms(x2, D, r2, broad), r2, strict=True):
        np.testing.assert_allclose(got, direct / (x2 + rk), rtol=2e-15, atol=0.0)


@pytest.mark.parametrize("engine", ["numpy", "numba"])
def test_passes_of_one_train_share_its_window_kernel_to_the_bit(engine):
    # The kernel is computed once per distinct train: a history of repeated consists gives each pass
    # what it gets alone, and a train differing in one offset's last bit is its own.
    layout, length, _, _ = _mixed_trains(30, 4)
    rows = np.random.default_rng(5).integers(0, 30, 400)
    many = layout.take(rows)
    first, inverse = passby_axles.distinct_trains(many, length[rows])
    assert len(first) == len(np.unique(rows)) and np.array_equal(rows[first][inverse], rows)
    got = passby_axles.window_kernels(many, length[rows], D, [R1, R2], engine)
    alone = np.stack([passby_axles.window_kernels(layout.take(np.array([i])), length[i:i + 1], D,
                                                  [R1, R2], engine)[:, 0] for i in rows], axis=1)
    np.testing.assert_array_equal(got, alone)
    nudged = axle_layout.AxleLayout(many.vehicles, many.pitch_m, many.offsets_m.copy())
    nudged.offsets_m[7, 0] = np.nextafter(nudged.offsets_m[7, 0], np.inf)
    assert len(passby_axles.distinct_trains(nudged, length[rows])[0]) == len(first) + 1
