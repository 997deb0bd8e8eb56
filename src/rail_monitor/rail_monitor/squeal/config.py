"""The site's squeal parameters: the wheel mode, the k3 convention, a creep curve per friction
state, the receiver and the risk thresholds."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, resolve, section, values_of, values_type
from rail_monitor.core.passes import FRICTION_NAMES
from rail_monitor.models import squeal

# SquealPrediction.RISK_* values.
RISK_NONE, RISK_LOW, RISK_MEDIUM, RISK_HIGH = range(4)

# Creep curves per friction state (k1 = friction peak, k2 = sliding slope per unit xi').
# Dry: the UQ seminar paper's rig values (k1 = 0.27, k2 = -0.02, its section 3.3) rounded to a rail steel
# peak of 0.3; wet: lower peak, milder fall; friction modifier: mu about 0.35 with a positive
# slope (the paper's section 2.1 and its ref. [12]); contaminated (leaf film): low adhesion. Site-tunable.
CREEP_DEFAULTS: dict[str, tuple[float, float]] = {
    "dry": (0.30, -0.02),
    "wet": (0.20, -0.008),
    "friction_modifier": (0.35, 0.01),
    "contaminated": (0.10, -0.01),
}

SQUEAL_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("modal_mass_kg", 40.0, "Modal mass of the squealing wheel mode at the contact, lateral [kg].",
              0.01, 1.0e4),
    ParamSpec("modal_damping_nspm", 60.0, "Modal damping c of the mode [N s/m] (60: damping ratio 1e-4, an "
              "undamped wheel).", 0.0, 1.0e6),
    ParamSpec("modal_stiffness_npm", 2.27e9, "Modal stiffness k of the mode [N/m] (with 40 kg: 1.2 kHz).",
              1.0, 1.0e13),
    ParamSpec("k3_convention", "kalker_unit", "How k3 follows from Kalker's C22 (models.squeal."
              "lateral_creep_stiffness).", choices=squeal.K3_CONVENTIONS),
    ParamSpec("k3_n", 0.0, "Lateral creep stiffness k3 given directly [N]; 0: from contact mechanics.", 0.0, 1.0e12),
    *(
        spec
        for state, (k1, k2) in CREEP_DEFAULTS.items()
        for spec in (
            ParamSpec(f"creep.{state}.k1", k1, f"Friction peak k1 of the {state} creep curve [-].", 0.01, 1.5),
            ParamSpec(f"creep.{state}.k2", k2, f"Sliding-branch slope k2 of the {state} creep curve, per unit "
                      "normalised creepage [-] (< 0 falling).", -0.5, 0.5),
        )
    ),
    ParamSpec("receiver_distance_m", 7.5, "Distance from the wheel to the receiver [m].", 0.05, 1000.0),
    ParamSpec("radiating_area_m2", 0.9, "Radiating area of the wheel (both sides) [m2].", 0.001, 10.0),
    ParamSpec("radiation_efficiency", 1.0, "Radiation efficiency of the squealing mode [-].", 0.0, 2.0),
    ParamSpec("spatial_average", 0.5, "Surface-averaged over contact-point squared velocity [-].", 0.0, 1.0),
    ParamSpec("reference_amplitude_mps", 1.0, "A w_ref of the relative level 20 lg(A w / A w_ref) [m/s].",
              1.0e-6, 100.0),
    ParamSpec("background_level_dba", 80.0, "Other noise of a pass at the receiver (rolling noise), against "
              "which a friction modifier's benefit is judged [dB(A)].", 0.0, 200.0),
    ParamSpec("risk_medium_dba", 85.0, "Squeal level from which the risk is medium [dB(A)].", 0.0, 200.0),
    ParamSpec("risk_high_dba", 95.0, "Squeal level from which the risk is high [dB(A)].", 0.0, 200.0),
)


def _creep(self, friction_state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """k1, k2 [-] per pass for TrainPass.FRICTION_* values."""
    k1 = np.full(friction_state.shape, np.nan)
    k2 = np.full(friction_state.shape, np.nan)
    for code, name in FRICTION_NAMES.items():
        sel = friction_state == code
        k1[sel], k2[sel] = getattr(self, f"creep_{name}_k1"), getattr(self, f"creep_{name}_k2")
    return k1, k2


SquealConfig = values_type(
    "SquealConfig", SQUEAL_SPECS, "The site's squeal parameters (names and units as in SQUEAL_SPECS; "
    "creep.dry.k1 is creep_dry_k1), and creep(friction_state), the creep curve of each pass.", __name__,
    creep=_creep)


def squeal_config(values: Mapping[str, Any], prefix: str = "squeal.") -> SquealConfig:
    """Checked squeal parameters from flat parameter values (keys under prefix)."""
    values = resolve(SQUEAL_SPECS, section(values, prefix), where=prefix, strict=True)
    if values["risk_high_dba"] < values["risk_medium_dba"]:
        raise ConfigError(f"parameter '{prefix}risk_high_dba' must not be below '{prefix}risk_medium_dba'")
    return values_of(SquealConfig, values)
