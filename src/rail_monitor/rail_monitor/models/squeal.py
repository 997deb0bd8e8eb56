"""Wheel squeal: one lateral wheel mode driven by a falling lateral creep curve.

Model (the UQ paper [1]_, section 2.3, eqs. 3-5; docs/models.md, "Wheel squeal")::

    m y'' + c y' + k y = -mu(xi') W,      xi' = (Vc + y') k3 / (V0 W),      Vc = V0 sin(theta)
    mu = k1 xi'                 for xi' <= 1    (adhesion branch,  slope s1 = k1 k3 / V0 [N s/m])
    mu = k1 + k2 (xi' - 1)      for xi' > 1     (falling branch,   slope s2 = k2 k3 / V0 [N s/m])

The critical creepage is zeta_c = W / k3 and the critical slip velocity u_s = zeta_c V0. Small
oscillations about the sliding state see the damping c + s2 (UQ paper eq. 5): squeal needs
c + s2 < 0 and Vc > u_s.

Limit cycle (our derivation; it corrects the sign of the k2 k3 term of the UQ paper's eq. 7).
Take y' = A w cos(wt) and require that the friction force does no net work against the
damper over one cycle. With D = Vc - u_s, the contact adheres (xi' <= 1) on the arc where
A w cos(wt) < -D, of half-angle phi with cos(phi) = D / (A w). The work of the adhesion
branch over that arc is (s1 - s2) (A w)^2 (2 phi - sin 2 phi) / 2 per cycle (in wt), that of
the damper and of the falling branch pi (c + s2) (A w)^2; their sum vanishes when::

    sin(2 phi) - 2 phi = 2 pi (V0 c + k2 k3) / (k3 (k1 - k2)),      A w = (Vc - zeta_c V0) / cos(phi)

A root 0 < phi <= pi/2 exists while c + s2 < 0 and s1 + s2 + 2 c >= 0. The closed form assumes
no reverse slip (the velocity never drives the creepage below -zeta_c), i.e. A w <= Vc + u_s,
and a falling branch that stays above mu = 0 over the cycle. Past either limit, or when no root
exists, the same balance is solved over the whole curve (:func:`harmonic_balance_amplitude`:
reverse slip and the zero-friction floor included, the integral over the cycle taken
numerically) and the regime is REGIME_REVERSE_SLIP. The velocity stays sinusoidal to within a
few per cent because the friction force is a small fraction of the mode's spring force, so
both forms agree with direct integration of the ODE
(:func:`rail_monitor.models.squeal_ode.simulate_limit_cycle`) to better than 2 % across the
regimes (tests).

k3 conventions (the lateral creep stiffness of the normalised curve) are in
:data:`K3_CONVENTIONS`; see :func:`lateral_creep_stiffness` for which one reproduces the UQ paper.

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and acoustic
   phenomena", seminar paper, sections 2.3 and 3 (eqs. 3-7, Figures 5-7).
.. [2] J. J. Kalker, *Three-Dimensional Elastic Bodies in Rolling Contact*, Kluwer Academic Publishers,
   Dordrecht, 1990.
.. [3] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
   Elsevier, Oxford, 2009, chapter 9 (curve squeal).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rail_monitor.models.hertz import HertzContact
from rail_monitor.models.kalker import lateral_creep_coefficient
from rail_monitor.models.squeal_balance import (
    FULL_BALANCE,
    BalanceResolution,
    critical_slip_velocity,
    harmonic_balance_amplitude,
)

FloatArray = NDArray[np.float64]

# SquealPrediction.REGIME_* values.
REGIME_STABLE, REGIME_LIMIT_CYCLE, REGIME_REVERSE_SLIP = 0, 1, 2
REGIME_NAMES = {REGIME_STABLE: "stable", REGIME_LIMIT_CYCLE: "limit cycle",
                REGIME_REVERSE_SLIP: "limit cycle, reverse slip"}  # or zero friction: the whole curve

K3_CONVENTIONS = ("reduced_kalker", "kalker_unit", "kalker_peak", "saturation_3x")

# The friction peak k1 of the UQ paper's rig (section 3.3), on which the reduction factor k_A of
# the reduced_kalker convention is calibrated.
RIG_PEAK_FRICTION = 0.27


def shear_modulus(young_pa: ArrayLike, poisson: ArrayLike) -> FloatArray:
    """Shear modulus of an isotropic elastic material, G = E / (2 (1 + nu)).

    Parameters
    ----------
    young_pa : array_like
        Young's modulus E [Pa].
    poisson : array_like
        Poisson's ratio nu [-].

    Returns
    -------
    ndarray
        Shear modulus G [Pa].

    References
    ----------
    .. [1] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, section 2.2.
    """
    return np.asarray(young_pa, float) / (2.0 * (1.0 + np.asarray(poisson, float)))


def kalker_lateral_stiffness(contact: HertzContact, young_pa: ArrayLike, poisson: ArrayLike) -> FloatArray:
    """Kalker's linear lateral creep force per unit creepage, G a b C22, of a Hertz contact.

    The two bodies are of the same material; C22 is
    :func:`rail_monitor.models.kalker.lateral_creep_coefficient` at the contact's a/b (a along rolling).

    Parameters
    ----------
    contact : HertzContact
        The contact ellipse, semi-axes a (rolling) and b (lateral) [m] (models.hertz).
    young_pa, poisson : array_like
        Young's modulus E [Pa] and Poisson's ratio nu [-] of both bodies.

    Returns
    -------
    ndarray
        G a b C22 [N].

    References
    ----------
    .. [1] J. J. Kalker, *Three-Dimensional Elastic Bodies in Rolling Contact*, Kluwer Academic
       Publishers, Dordrecht, 1990 (the linear creep coefficients).
    """
    c22 = lateral_creep_coefficient(contact.a / contact.b, poisson)
    return shear_modulus(young_pa, poisson) * contact.a * contact.b * c22


def lateral_creep_stiffness(kalker_stiffness: ArrayLike, mu0: ArrayLike, convention: str = "reduced_kalker",
                            reduction_factor: ArrayLike = RIG_PEAK_FRICTION) -> FloatArray:
    """The lateral creep stiffness k3 that normalises the creepage, xi' = zeta k3 / W.

    The creep curve saturates at the creepage zeta_c = W / k3 and its adhesion slope is k1 k3 per
    unit creepage. Conventions:

    ``reduced_kalker`` (default)
        k3 = k_A G a b C22 / mu0: the adhesion branch is Kalker's slope times a reduction factor
        k_A [-] (reduction_factor), the same for every friction state, so the saturation creepage
        zeta_c = mu0 W / (k_A G a b C22) scales with each state's friction peak, as it does for
        any creep law whose initial slope is Kalker's and whose limit is Coulomb's. Kalker's
        linear theory overestimates measured initial creep slopes and reduction factors well
        below 1 are needed to fit measured curves [2]_. k_A is calibrated once on the UQ paper's
        rig: k_A = 0.27, the rig's friction peak, gives the rig k3 = G a b C22 = 1.48e5 N
        (zeta_c = 0.0068), with which the paper's A w = 0.33 m/s at Vc = 0.39 m/s, halving at
        -34 % Vc, are reproduced (tests). For full-size wheels on dry rail it puts the squeal
        onset at 5-10 mrad angle of attack, as observed.
    ``kalker_unit``
        k3 = G a b C22 whatever the friction: the saturation creepage does not depend on mu0
        (version 0.2's default; equal to ``reduced_kalker`` where mu0 = k_A).
    ``kalker_peak``
        The UQ paper's eq. (4) read literally, xi' = zeta G a b C22 / (mu0 W): k3 = G a b C22 / mu0,
        i.e. ``reduced_kalker`` with k_A = 1. For the UQ paper's rig this gives k3 = 5.5e5 N
        (zeta_c = 0.0018) and does not reproduce the UQ paper's Figures 6-7.
    ``saturation_3x``
        Saturation at three times the linear intercept (the cubic Vermeulen-Johnson curve
        saturates there): k3 = G a b C22 / (3 mu0).

    Parameters
    ----------
    kalker_stiffness : array_like
        Kalker's linear lateral creep force per unit creepage, G a b C22 [N]
        (:func:`kalker_lateral_stiffness`).
    mu0 : array_like
        The friction peak k1 [-].
    convention : str
        One of K3_CONVENTIONS [-].
    reduction_factor : array_like
        k_A of ``reduced_kalker`` [-].

    Returns
    -------
    ndarray
        k3 [N].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eq. 4.
    .. [2] O. Polach, "Creep forces in simulations of traction vehicles running on adhesion limit",
       *Wear* 258 (2005) 992-1000.
    """
    g_ab_c22 = np.asarray(kalker_stiffness, float)
    if convention == "reduced_kalker":
        return np.asarray(reduction_factor, float) * g_ab_c22 / np.asarray(mu0, float)
    if convention == "kalker_unit":
        return g_ab_c22 * np.ones_like(np.asarray(mu0, float))
    if convention == "kalker_peak":
        return g_ab_c22 / np.asarray(mu0, float)
    if convention == "saturation_3x":
        return g_ab_c22 / (3.0 * np.asarray(mu0, float))
    raise ValueError(f"unknown k3 convention {convention!r}; use one of {K3_CONVENTIONS}")


def effective_damping(damping: ArrayLike, k2: ArrayLike, k3: ArrayLike, speed: ArrayLike) -> FloatArray:
    """The damping seen by small oscillations about the sliding state, c + k2 k3 / V0 (UQ eq. 5).

    Negative means unstable: the falling branch of the creep curve feeds the mode more energy than
    its damping takes.

    Parameters
    ----------
    damping : array_like
        Modal damping c [N s/m].
    k2 : array_like
        Slope of mu against xi' on the sliding branch [-] (< 0 falling).
    k3 : array_like
        Lateral creep stiffness [N] (:func:`lateral_creep_stiffness`).
    speed : array_like
        Rolling speed V0 [m/s].

    Returns
    -------
    ndarray
        c + k2 k3 / V0 [N s/m].

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eq. 5.
    """
    return np.asarray(damping, float) + np.asarray(k2, float) * np.asarray(k3, float) / np.asarray(speed, float)


class LimitCycle(NamedTuple):
    """Squeal state per case (arrays broadcast over the inputs).

    amplitude: lateral velocity amplitude A w [m/s] (0 when stable; by harmonic balance over
    the whole creep curve where the closed form does not hold); closed_form: the closed-form
    A w [m/s] wherever a root exists (NaN elsewhere); phi: half the adhesion angle [rad] (NaN
    without a root); regime: REGIME_*; unstable: squeal conditions met; effective_damping:
    c + s2 [N s/m]; critical_slip: u_s [m/s]; friction_positive: the falling branch stays above
    mu = 0 up to the largest creepage of the cycle (where it does not, the UQ paper's curve is
    extrapolated with its floor at zero friction).
    """

    amplitude: FloatArray
    closed_form: FloatArray
    phi: FloatArray
    regime: NDArray[np.int8]
    unstable: NDArray[np.bool_]
    effective_damping: FloatArray
    critical_slip: FloatArray
    friction_positive: NDArray[np.bool_]


def _solve_x_minus_sin(q: FloatArray) -> FloatArray:
    """x in [0, pi] with x - sin x = q for 0 <= q <= pi (vectorised Newton).

    Starts from the small-x inverse x = (6 q)^(1/3), exact as q -> 0 and within 16 % at q = pi.
    x - sin x is increasing and convex on [0, pi], so after the first step the iterates approach
    the root monotonically from above; eight steps reach machine precision.
    """
    x = np.minimum(np.cbrt(6.0 * q), np.pi)
    for _ in range(8):
        slope = 1.0 - np.cos(x)
        step = np.where(slope > 1e-300, (x - np.sin(x) - q) / np.where(slope > 1e-300, slope, 1.0), 0.0)
        x = np.clip(x - step, 0.0, np.pi)
    return x


def limit_cycle_amplitude(
    speed: ArrayLike,
    crabbing: ArrayLike,
    load: ArrayLike,
    damping: ArrayLike,
    k1: ArrayLike,
    k2: ArrayLike,
    k3: ArrayLike,
    resolution: BalanceResolution = FULL_BALANCE,
) -> LimitCycle:
    """Squeal velocity amplitude by energy balance over one cycle (module docstring; UQ eq. 7 corrected).

    The closed form holds while the contact does not slip backwards and the falling branch stays
    above mu = 0; past either, the balance is solved over the whole curve
    (:func:`rail_monitor.models.squeal_balance.harmonic_balance_amplitude`).

    Parameters
    ----------
    speed : array_like
        Rolling speed V0 [m/s].
    crabbing : array_like
        Crabbing velocity Vc [m/s] (sign ignored: the creep curve is odd).
    load : array_like
        Normal load W [N].
    damping : array_like
        Modal damping c [N s/m].
    k1 : array_like
        Friction peak, the slope of mu against xi' on the adhesion branch [-].
    k2 : array_like
        Slope of mu against xi' on the sliding branch [-] (< 0 falling).
    k3 : array_like
        Lateral creep stiffness [N] (:func:`lateral_creep_stiffness`).
    resolution : BalanceResolution
        Grid of the harmonic balance where the closed form does not hold [-].

    Returns
    -------
    LimitCycle
        Amplitude A w [m/s], the closed form [m/s], phi [rad], regime, instability, effective
        damping [N s/m], critical slip [m/s], friction positive over the cycle; broadcast over the
        inputs.

    References
    ----------
    .. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
       acoustic phenomena", seminar paper, section 2.3, eqs. 3-7, Figures 6-7.
    """
    v0, vc, w, c, k1, k2, k3 = np.broadcast_arrays(
        *(np.asarray(x, float) for x in (speed, crabbing, load, damping, k1, k2, k3))
    )
    vc = np.abs(vc)
    u_s = critical_slip_velocity(v0, w, k3)
    c_eff = effective_damping(c, k2, k3, v0)
    s1, s2 = k1 * k3 / v0, k2 * k3 / v0
    # The floored curve (creep_force) is flat where the falling branch would cross mu = 0.
    unstable = (c_eff < 0.0) & (vc > u_s) & (k1 + k2 * (vc / u_s - 1.0) > 0.0)
    # sin 2phi - 2phi = 2 pi (c + s2) / (s1 - s2)  <=>  x - sin x = q with x = 2 phi.
    q = -2.0 * np.pi * c_eff / np.where(s1 > s2, s1 - s2, np.inf)
    has_root = unstable & (q <= np.pi)
    x = _solve_x_minus_sin(np.where(has_root, q, 0.0))
    phi = np.where(has_root, 0.5 * x, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):  # phi = pi/2 (q = pi): unbounded amplitude
        closed = (vc - u_s) / np.cos(phi)  # NaN where there is no root
    with np.errstate(invalid="ignore"):
        floor_clear = k1 + k2 * np.maximum((vc + closed) / u_s - 1.0, 0.0) > 0.0
    valid = has_root & (closed <= vc + u_s) & floor_clear
    regime = np.where(~unstable, REGIME_STABLE, np.where(valid, REGIME_LIMIT_CYCLE, REGIME_REVERSE_SLIP))
    amplitude = np.where(regime == REGIME_LIMIT_CYCLE, closed, 0.0)
    whole = regime == REGIME_REVERSE_SLIP
    if whole.any():
        amplitude[whole] = harmonic_balance_amplitude(v0[whole], vc[whole], w[whole], c[whole], k1[whole],
                                                      k2[whole], k3[whole], resolution)
    with np.errstate(invalid="ignore"):
        xi_max = (vc + np.where(unstable, amplitude, 0.0)) / u_s
        friction_positive = k1 + k2 * np.maximum(xi_max - 1.0, 0.0) > 0.0
    return LimitCycle(amplitude, closed, phi, regime.astype(np.int8), unstable, c_eff, u_s, friction_positive)


