"""Bands, level arithmetic and pass-by levels (models.iec61260, models.levels, models.passby)."""

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from rail_monitor.models import levels, passby, passby_kernel, passby_paths

RECEIVER = passby.Receiver(7.5, 1.2, 0.05, 0.0, 1.0)


def _g(x, d, r):
    return (0.01 / (r * r + x * x) + 0.99 * d * d / ((d * d + x * x) * (r * r + x * x))) / (4 * np.pi)


@pytest.mark.parametrize("d, r", [(7.5, 7.59), (7.5, 7.5), (3.0, 5.0)])
def test_kernel_antiderivatives_match_quadrature(d, r):
    """Closed forms against adaptive quadrature of the point-source kernel (independent method), 1e-9."""
    for x in (0.5, 7.0, 40.0):
        val, _ = quad(_g, 0.0, x, args=(d, r), epsabs=1e-14, epsrel=1e-12)
        assert passby_kernel.kernel_antiderivative(x, d, r) == pytest.approx(val, rel=1e-9)
    total, _ = quad(_g, -np.inf, np.inf, args=(d, r), epsabs=1e-14, epsrel=1e-12)
    assert passby_kernel.kernel_total(d, r) == pytest.approx(total, rel=1e-9)
    length = 60.0
    g = passby_kernel.kernel_antiderivative
    mean, _ = quad(lambda s: float(g(s, d, r) - g(s - length, d, r)), 0.0, length, epsabs=1e-14, epsrel=1e-12)
    assert passby_kernel.kernel_window_mean(length, d, r) == pytest.approx(mean / length, rel=1e-8)


def test_a_long_train_approaches_the_infinite_line_and_tel_exceeds_the_window_level():
    band = np.array([0])                                 # 1 kHz
    lw = np.array([[90.0]]) - levels.a_weighted(0.0, band)  # so that the A-weighted level is 90 dB
    short = passby.pass_by(lw, band, [20.0], [20.0], RECEIVER)
    long_ = passby.pass_by(lw, band, [20000.0], [20.0], RECEIVER)
    # Infinite incoherent line: p^2 / p0^2 = W' (T_direct + T_image), T in closed form.
    (r1, _), (r2, _) = RECEIVER.paths()
    line = 90.0 + 10 * np.log10(passby_kernel.kernel_total(7.5, r1) + passby_kernel.kernel_total(7.5, r2))
    assert long_.lpaeq_tp_dba[0] == pytest.approx(line, abs=0.01)
    assert long_.lpafmax_dba[0] == pytest.approx(line, abs=0.01)
    assert short.tel_dba[0] == pytest.approx(line, abs=1e-9)       # TEL: exposure over Tp, any length
    assert short.lpaeq_tp_dba[0] < short.lpafmax_dba[0] < short.tel_dba[0]


def test_lpaeq_weights_give_the_pass_bys_lpaeq_for_any_spectrum():
    # LpAeq,Tp is linear in the power per metre: the weights of a line times a spectrum, summed
    # over bands, against pass_by's path-by-path sum (the same numbers but for rounding).
    rng = np.random.default_rng(2)
    band = np.arange(-10, 11)
    lw = rng.uniform(60.0, 100.0, (50, len(band)))
    length, speed = rng.uniform(20.0, 600.0, 50), rng.uniform(5.0, 40.0, 50)
    gain_db = rng.uniform(-3.0, 3.0, len(band))
    g = passby.pass_geometry(band, length, speed, RECEIVER)
    want = passby.pass_by(lw, band, length, speed, RECEIVER, gain_db, time_weighted=False, geometry=g).lpaeq_tp_dba
    got = levels.level(np.sum(levels.power(lw) * passby_paths.lpaeq_weights(g, levels.power(gain_db)), axis=-1))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_f_time_weighting_matches_a_time_integration():
    """LpAFmax against solve_ivp of tau dy/dt = x - y on the same time history (IEC 61672-1 F), 0.05 dB."""
    d = RECEIVER.distance_m
    (r1, _), (r2, _) = RECEIVER.paths()
    length, speed = 12.0, 30.0

    def x(t):
        s = speed * t
        g = passby_kernel.kernel_antiderivative
        return float(g(s, d, r1) - g(s - length, d, r1) + g(s, d, r2) - g(s - length, d, r2))

    sol = solve_ivp(lambda t, y: (x(t) - y) / passby_kernel.F_TIME_CONSTANT_S, (-10.0, 10.0), [0.0], max_step=0.002,
                    rtol=1e-9, atol=1e-14)
    got = passby.pass_by(np.array([[0.0]]), np.array([0]), [length], [speed], RECEIVER).lpafmax_dba[0]
    assert got == pytest.approx(10 * np.log10(sol.y[0].max()), abs=0.05)


def test_free_field_point_limit_and_ground():
    """A short train far away is a point source: Lp(TEL over Tp) -> L_W - 10 lg(4 pi r^2) + 10 lg(L) per path."""
    far = passby.Receiver(200.0, 0.0, 0.0, 0.0, 0.0)
    out = passby.pass_by(np.array([[100.0]]), np.array([0]), [1.0], [10.0], far)
    expected = 100.0 - 10 * np.log10(4 * np.pi * 200.0**2)            # 1 m of train, broadside
    assert out.lpaeq_tp_dba[0] == pytest.approx(expected, abs=0.01)
    hard = passby.pass_by(np.array([[100.0]]), np.array([0]), [1.0], [10.0],
                          passby.Receiver(200.0, 0.0, 0.0, 0.0, 1.0))
    assert hard.lpaeq_tp_dba[0] - out.lpaeq_tp_dba[0] == pytest.approx(10 * np.log10(2), abs=0.01)


def test_the_exponential_average_is_lfilter_step_for_step():
    # The F-weighting recursion against scipy.signal.lfilter (direct form II transposed), bit for bit.
    from scipy.signal import lfilter

    a = np.exp(-1.0 / 8)
    for rows in (1, passby_kernel.FEW_ROWS, 40):  # plain floats for a few series, numpy rows for many
        x = np.random.default_rng(rows).lognormal(0.0, 2.0, (rows, 73))
        want, _ = lfilter([1.0 - a], [1.0, -a], x, axis=1, zi=a * x[:, :1])
        assert np.array_equal(passby_kernel.exponential_average(x, a), want)
