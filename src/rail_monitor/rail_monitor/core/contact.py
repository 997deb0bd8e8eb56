"""The contact state of each pass: one computation that every model takes.

Per pass: the normal load W [N] (the pass's wheel load, or its class's nominal load), the Hertz
patch of the class's wheel on the rail head (models.hertz), the lateral creepage
zeta = sin|angle of attack| and the crabbing velocity Vc = V0 zeta, the friction state's creep
curve (k1, k2) and its lateral creep stiffness k3 (models.squeal.lateral_creep_stiffness, under
the site's convention), the saturation creepage zeta_c = W / k3 and the regime: full sliding where
zeta > zeta_c (Vc > u_s = zeta_c V0), partial slip otherwise.

The squeal model takes the creep curve, k3 and Vc; the corrugation kernel takes the regime (its
K_b changes sign in full sliding, docs/models.md "Sliding") and the class's patch.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from rail_monitor.core.passes import PassTable
from rail_monitor.core.site import Site
from rail_monitor.models import squeal
from rail_monitor.models.hertz import HertzContact

REGIME_PARTIAL_SLIP, REGIME_FULL_SLIDING = 0, 1
REGIME_NAMES = {REGIME_PARTIAL_SLIP: "partial slip", REGIME_FULL_SLIDING: "full sliding"}


class ContactState(NamedTuple):
    """Contact of each pass (arrays of the passes' shape; units in brackets).

    load_n [N]; patch: the Hertz solution (semi-axes a along the rail and b [m], stiffness [N/m]);
    k1, k2 [-]: the creep curve; k3_n [N]; creepage [-]: lateral, sin|angle of attack|;
    saturation_creepage [-]: W / k3; crabbing_mps and critical_slip_mps: V0 times those [m/s];
    regime: REGIME_* (int8); kalker_n [N]: G a b C22 of the patch (None where the site sets k3_n),
    which does not depend on the friction state.
    """

    load_n: np.ndarray
    patch: HertzContact
    k1: np.ndarray
    k2: np.ndarray
    k3_n: np.ndarray
    creepage: np.ndarray
    saturation_creepage: np.ndarray
    crabbing_mps: np.ndarray
    critical_slip_mps: np.ndarray
    regime: np.ndarray
    kalker_n: np.ndarray | None = None

    @property
    def full_sliding(self) -> np.ndarray:
        return self.regime == REGIME_FULL_SLIDING

    def at_speed(self, speed_mps: np.ndarray) -> ContactState:
        """The same contacts at other speeds [m/s] (any shape broadcasting with the passes'): Vc and
        u_s scale with V0, nothing else depends on it (the advice's what-if speeds)."""
        return self._replace(**_speed_terms(speed_mps, self.creepage, self.load_n, self.k3_n))


def _speed_terms(speed_mps: np.ndarray, creepage: np.ndarray, load_n: np.ndarray, k3_n: np.ndarray) -> dict:
    """The fields of a ContactState proportional to V0: Vc = V0 zeta and u_s = V0 W / k3 [m/s]."""
    critical = squeal.critical_slip_velocity(speed_mps, load_n, k3_n)
    return {"crabbing_mps": speed_mps * creepage, "critical_slip_mps": critical}


def wheel_radius(site: Site, vehicle_class: np.ndarray) -> np.ndarray:
    """Rolling radius [m] of each pass's class (half its nominal wheel diameter)."""
    return site.per_pass(vehicle_class, "wheel_diameter_m").astype(np.float64) / 2.0


def kalker_stiffness(site: Site, patch: HertzContact) -> np.ndarray | None:
    """G a b C22 [N] of each patch, or None where the site sets k3_n (not needed)."""
    c = site.contact
    return None if c.k3_n > 0.0 else squeal.kalker_lateral_stiffness(patch, c.young_modulus_pa, c.poisson_ratio)


def creep_stiffness(site: Site, patch: HertzContact, k1: np.ndarray, kalker: np.ndarray | None = None) -> np.ndarray:
    """k3 [N] per pass: the site's k3_n where given, else from G a b C22 under its convention
    (kalker: G a b C22 of the patch when already computed, :func:`kalker_stiffness`)."""
    c = site.contact
    if c.k3_n > 0.0:
        return np.full(np.shape(k1), c.k3_n)
    if kalker is None:
        kalker = kalker_stiffness(site, patch)
    return squeal.lateral_creep_stiffness(kalker, k1, c.k3_convention, c.creep_reduction_factor)


def contact_state(site: Site, passes: PassTable, friction_state: np.ndarray | None = None,
                  own: ContactState | None = None) -> ContactState:
    """The contact state of each pass (valid for the site, class defaults filled:
    :func:`rail_monitor.core.passes.with_class_defaults`), in its own friction state or, where
    given, in friction_state (TrainPass.FRICTION_* per pass) instead. own: the passes' contact
    state when already computed, whose patch and Kalker stiffness are taken (neither depends on
    the friction state)."""
    friction = passes.friction_state if friction_state is None else friction_state
    return contact_state_of(site, passes.vehicle_class, friction, passes.wheel_load_n,
                            np.sin(np.abs(passes.angle_of_attack_rad)), passes.speed_mps,
                            *((own.patch, own.kalker_n) if own is not None else ()))


def contact_state_of(site: Site, vehicle_class: np.ndarray, friction_state: np.ndarray, load_n: np.ndarray,
                     creepage: np.ndarray, speed_mps: np.ndarray, patch: HertzContact | None = None,
                     kalker: np.ndarray | None = None) -> ContactState:
    """The contact state from its inputs per pass: class names, TrainPass.FRICTION_* codes, wheel
    load [N], lateral creepage [-] and speed [m/s] (patch and kalker: the passes' Hertz patch and
    its G a b C22 [N] when already computed)."""
    if patch is None:
        patch = site.contact_patch(wheel_radius(site, vehicle_class), load_n)
    if kalker is None:
        kalker = kalker_stiffness(site, patch)
    k1, k2 = site.contact.creep(friction_state)
    k3 = creep_stiffness(site, patch, k1, kalker)
    saturation = load_n / k3
    regime = np.where(creepage > saturation, REGIME_FULL_SLIDING, REGIME_PARTIAL_SLIP).astype(np.int8)
    return ContactState(load_n=load_n, patch=patch, k1=k1, k2=k2, k3_n=k3, creepage=creepage,
                        saturation_creepage=saturation, regime=regime, kalker_n=kalker,
                        **_speed_terms(speed_mps, creepage, load_n, k3))
