"""Direct time integration of the squeal ODE: the independent check of the energy balance.

The ODE is :mod:`rail_monitor.models.squeal`'s (the UQ paper's eqs. 3-5), m y'' + c y' + k y =
-mu(xi') W with xi' = (Vc + y') k3 / (V0 W) on the same floored, odd creep curve
(:func:`rail_monitor.models.squeal_balance.creep_force`), integrated with scipy's DOP853 without events
until the velocity amplitude settles.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from rail_monitor.models.squeal_balance import creep_force

FloatArray = NDArray[np.float64]


class TimeDomainResult(NamedTuple):
    """Steady amplitude from direct integration: amplitude [m/s] (half the peak-to-peak wheel
    velocity over the last cycles), t [s] and velocity [m/s] samples of the last cycles,
    cycles integrated, and whether the envelope had settled."""

    amplitude: float
    t: FloatArray
    velocity: FloatArray
    cycles: int
    settled: bool


def simulate_limit_cycle(
    speed: float,
    crabbing: float,
    load: float,
    mass: float,
    damping: float,
    stiffness: float,
    k1: float,
    k2: float,
    k3: float,
    *,
    initial_velocity: float | None = None,
    max_cycles: int = 20000,
    chunk_cycles: int = 200,
    settle_tol: float = 1e-5,
    rtol: float = 1e-8,
) -> TimeDomainResult:
    """The squeal ODE integrated in time with scipy's DOP853, no events (module docstring).

    Starts at the static equilibrium with a small velocity disturbance (default 1 % of Vc),
    integrates in chunks of ``chunk_cycles`` natural periods and stops when the velocity amplitude
    of successive chunks changes by less than ``settle_tol`` (relative), or after ``max_cycles``.
    Independent of the closed form: used by the tests to check it, and available to users.

    Parameters
    ----------
    speed, crabbing, load, damping, k1, k2, k3 : float
        One case in the units of :func:`rail_monitor.models.squeal.limit_cycle_amplitude`:
        V0 [m/s], Vc [m/s], W [N], c [N s/m], k1 [-], k2 [-], k3 [N].
    mass : float
        Modal mass m [kg].
    stiffness : float
        Modal stiffness k [N/m].
    initial_velocity : float, optional
        The disturbance [m/s] (default 1 % of Vc).
    max_cycles, chunk_cycles : int
        Natural periods at most, and per chunk [-].
    settle_tol : float
        Relative change of the amplitude that counts as settled [-].
    rtol : float
        The integrator's relative tolerance [-].

    Returns
    -------
    TimeDomainResult
        Amplitude [m/s], the last cycles' times [s] and velocities [m/s], cycles [-], settled or not.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eqs. 3-5.
    .. [2] E. Hairer, S. P. Norsett and G. Wanner, *Solving Ordinary Differential Equations I*,
       2nd ed., Springer, Berlin, 1993 (DOP853, Dormand and Prince's explicit method of order 8).
    """
    from scipy.integrate import solve_ivp  # lazy: only the tests and --ode integrate

    omega = np.sqrt(stiffness / mass)
    period = 2.0 * np.pi / omega

    scale = k3 / (speed * load)  # xi' per unit slip velocity [s/m]

    def rhs(_t: float, s: FloatArray) -> list[float]:
        # Scalar arithmetic: the solver calls this ~1e5 times; same curve as creep_force.
        y, v = s
        xi = (crabbing + v) * scale
        ax = abs(xi)
        mu = k1 * ax if ax <= 1.0 else max(k1 + k2 * (ax - 1.0), 0.0)
        f = math.copysign(mu * load, xi)
        return [v, (-damping * v - stiffness * y - f) / mass]

    y_static = -float(creep_force(crabbing, speed, load, k1, k2, k3)) / stiffness
    state = np.array([y_static, 0.01 * abs(crabbing) if initial_velocity is None else initial_velocity])
    t0, previous, cycles = 0.0, np.nan, 0
    samples = 64
    while True:
        t1 = t0 + chunk_cycles * period
        t_eval = np.linspace(t1 - 20 * period, t1, 20 * samples * 8 + 1)
        sol = solve_ivp(rhs, (t0, t1), state, method="DOP853", rtol=rtol, atol=rtol * 1e-3 * max(abs(crabbing), 1e-6),
                        t_eval=t_eval, max_step=period / 4)
        v = sol.y[1]
        amp = 0.5 * float(v.max() - v.min())
        cycles += chunk_cycles
        state, t0 = sol.y[:, -1], t1
        settled = np.isfinite(previous) and abs(amp - previous) <= settle_tol * max(amp, 1e-12)
        if settled or cycles >= max_cycles:
            return TimeDomainResult(amp, sol.t, v, cycles, bool(settled))
        previous = amp
