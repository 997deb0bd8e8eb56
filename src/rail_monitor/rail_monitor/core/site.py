"""The site: its identity, curve, wheel-rail contact, track and rolling-stock table.

The specs below are the single source of the site parameters' names, defaults, units and
ranges; nodes declare them as ROS 2 parameters and :mod:`rail_monitor.site_file` reads them from
a site parameter file without ROS.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.friction import FRICTION_NAMES
from rail_monitor.core.params import ParamSpec, resolve, section, values_of
from rail_monitor.core.timeutil import time_zone
from rail_monitor.models import hertz
from rail_monitor.models.cnossos import TRACTION_TYPES
from rail_monitor.models.cnossos_roughness import BRAKE_TYPES
from rail_monitor.models.squeal import K3_CONVENTIONS, RIG_PEAK_FRICTION
from rail_monitor.models.track import Track

SITE_ID = ParamSpec("site_id", "site", "Site identifier, written to header.frame_id of every message.")
VEHICLE_CLASSES = ParamSpec("vehicle_classes", ["emu"], "Names of the vehicle classes of the rolling-stock table.")
SITE_SPECS: tuple[ParamSpec, ...] = (
    SITE_ID,
    ParamSpec("curve_radius_m", 250.0, "Radius of the curve at the site [m].", 10.0, 1.0e5),
    VEHICLE_CLASSES,
    ParamSpec("time_zone", "UTC", "IANA time zone of the site (e.g. Australia/Brisbane): local times in the report "
              "and exports; stamps stay UTC."),
)

# Creep curves per friction state (k1 = friction peak, k2 = sliding slope per unit xi'; the UQ
# paper's piecewise-linear curve, models.squeal). Dry: the UQ seminar paper's rig values
# (k1 = 0.27, k2 = -0.02, its section 3.3) rounded to a rail steel peak of 0.3. Friction modifier:
# mu about 0.35 with a positive slope (the paper's section 2.1 and its ref. [12]). Wet (0.2) and
# contaminated by a leaf film (0.1): lower peaks with dry rail's relative fall k2/k1 = -1/15 (the
# same curve shape scaled by the friction level; no measured curve per state is cited here: set a
# site's own). The saturation creepage scales with k1 (contact.k3_convention reduced_kalker).
CREEP_DEFAULTS: dict[str, tuple[float, float]] = {
    "dry": (0.30, -0.02),
    "wet": (0.20, -0.0133),
    "friction_modifier": (0.35, 0.01),
    "contaminated": (0.10, -0.0067),
}

# Wheel-rail contact, under contact.: one contact for every model (rail_monitor.core.contact: the
# contact state of a pass, from which squeal, the corrugation kernel and its regime follow).
CONTACT_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("young_modulus_pa", 210.0e9, "Young's modulus of wheel and rail steel [Pa].", 1.0e9, 1.0e12),
    ParamSpec("poisson_ratio", 0.28, "Poisson's ratio of wheel and rail steel [-].", 0.0, 0.5),
    ParamSpec("rail_head_radius_m", 0.3, "Transverse radius of the rail head at the contact [m].", 0.01, 100.0),
    ParamSpec("wheel_transverse_radius_m", 1.0e6, "Transverse radius of the wheel tread at the contact [m] "
              "(1e6: a conical tread).", 0.05, 1.0e9),
    ParamSpec("k3_convention", "reduced_kalker", "How the lateral creep stiffness k3 follows from Kalker's C22 "
              "(models.squeal.lateral_creep_stiffness).", choices=K3_CONVENTIONS),
    ParamSpec("creep_reduction_factor", RIG_PEAK_FRICTION, "Reduction factor k_A on Kalker's creep slope of the "
              "reduced_kalker convention [-] (0.27: calibrated on the UQ paper's rig).", 0.01, 1.0),
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
)

# Track, under track.: one track model for corrugation and rolling noise (models.track.Track;
# defaults: UIC60 on a typical ballasted track, see docs/models.md).
TRACK_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("young_modulus_pa", 210.0e9, "Young's modulus of the rail [Pa].", 1.0e9, 1.0e12),
    ParamSpec("poisson_ratio", 0.3, "Poisson's ratio of the rail [-].", 0.0, 0.5),
    ParamSpec("area_m2", 7.69e-3, "Rail cross-section area [m2] (UIC60: 7.69e-3).", 1.0e-4, 0.1),
    ParamSpec("second_moment_m4", 30.55e-6, "Vertical second moment of area of the rail [m4] (UIC60: 30.55e-6).",
              1.0e-7, 1.0e-3),
    ParamSpec("mass_per_length_kgpm", 60.4, "Rail mass per metre [kg/m].", 5.0, 500.0),
    ParamSpec("shear_coefficient", 0.4, "Timoshenko shear coefficient of the rail section [-].", 0.05, 1.0),
    ParamSpec("rail_loss_factor", 0.02, "Loss factor of the rail [-].", 0.0, 1.0),
    ParamSpec("pad_stiffness_npm", 350.0e6, "Rail pad stiffness per rail seat [N/m] (soft 100e6 to stiff 1e9).",
              1.0e6, 1.0e11),
    ParamSpec("pad_loss_factor", 0.25, "Rail pad loss factor [-].", 0.0, 2.0),
    ParamSpec("sleeper_mass_kg", 150.0, "Half-sleeper mass per rail seat [kg].", 1.0, 2000.0),
    ParamSpec("ballast_stiffness_npm", 50.0e6, "Ballast stiffness under a half sleeper [N/m].", 1.0e5, 1.0e10),
    ParamSpec("ballast_loss_factor", 1.0, "Ballast loss factor [-].", 0.0, 5.0),
    ParamSpec("sleeper_spacing_m", 0.6, "Sleeper spacing [m].", 0.2, 2.0),
)

# Per vehicle class, under vehicle.<name>.: rolling stock, then the traffic it runs in.
VEHICLE_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("axles_per_vehicle", 4, "Axles per vehicle [-].", 1, 12),
    ParamSpec("wheel_diameter_m", 0.84, "Nominal wheel diameter [m].", 0.3, 1.5),
    ParamSpec("brake_type", "disc", "Brake type (sets wheel roughness).", choices=BRAKE_TYPES),
    ParamSpec("freight", False, "Freight wagons: CNOSSOS-EU's superstructure term (eq. 2.3.9) is counted for "
              "freight vehicles only."),
    ParamSpec("traction", "none", "CNOSSOS-EU traction noise (Table G-5) of each vehicle of the class's trains, by "
              f"vehicle type (at constant speed; sources A and B): one of the edition's ({', '.join(TRACTION_TYPES)}) "
              "or the site's noise.cnossos_catalogue; none: no traction noise (wagons, coaches)."),
    ParamSpec("wheel_load_n", 60000.0, "Nominal static wheel load [N].", 1.0e3, 2.5e5),
    ParamSpec("unsprung_mass_kg", 600.0, "Unsprung mass per wheel (half a wheelset and what moves with it) "
              "[kg].", 50.0, 5000.0),
    ParamSpec("wheel_damping_ratio", 1.0e-4, "Damping ratio of the wheel's modes with two or more nodal "
              "diameters in the mechanics rolling-noise model [-] (1e-4: an untreated solid wheel; a wheel damper: "
              "1e-3 to 1e-2).", 1.0e-6, 0.5),
    ParamSpec("vehicle_length_m", 20.0, "Vehicle length over couplers [m].", 3.0, 40.0),
    ParamSpec("bogie_semi_wheelbase_m", 1.25, "Half the bogie wheelbase (axle to bogie centre) [m].", 0.3, 5.0),
    ParamSpec("bogie_centre_distance_m", 14.0, "Distance between the vehicle's bogie centres [m]: where its axles "
              "radiate in the pass-by (a moving point source per axle).", 0.0, 40.0),
    ParamSpec("traffic_share", 1.0, "Share of the site's trains of this class [-].", 0.0, 1.0),
    ParamSpec("vehicles_min", 3, "Fewest vehicles in a consist [-].", 1, 100),
    ParamSpec("vehicles_max", 6, "Most vehicles in a consist [-].", 1, 100),
    ParamSpec("speed_mean_mps", 19.0, "Mean pass speed of the class at the site [m/s].", 0.5, 100.0),
    ParamSpec("speed_sd_mps", 1.5, "Standard deviation of the pass speed [m/s].", 0.0, 30.0),
    ParamSpec("speed_min_mps", 8.0, "Lowest pass speed (the distribution is truncated) [m/s].", 0.5, 100.0),
    ParamSpec("speed_max_mps", 22.0, "Highest pass speed (line speed at the curve) [m/s].", 0.5, 100.0),
    # The squealing wheel mode (one lateral/axial mode at the contact, models.squeal) and its radiation.
    ParamSpec("squeal_mode_hz", 1200.0, "Natural frequency of the wheel's squealing mode [Hz].", 50.0, 2.0e4),
    ParamSpec("squeal_modal_mass_kg", 40.0, "Modal mass of that mode at the contact, lateral [kg].", 0.01, 1.0e4),
    ParamSpec("squeal_damping_ratio", 1.0e-4, "Modal damping ratio of that mode [-] (1e-4: an untreated wheel; a "
              "wheel damper raises it).", 0.0, 0.5),
    ParamSpec("wheel_radiating_area_m2", 0.9, "Radiating area of the wheel, both sides [m2].", 0.001, 10.0),
    ParamSpec("squeal_radiation_efficiency", 1.0, "Radiation efficiency of the squealing mode [-].", 0.0, 2.0),
)


@dataclass(frozen=True)
class VehicleClass:
    """One entry of the rolling-stock table (units as in VEHICLE_SPECS)."""

    name: str
    axles_per_vehicle: int
    wheel_diameter_m: float
    brake_type: str
    freight: bool
    traction: str
    wheel_load_n: float
    unsprung_mass_kg: float
    wheel_damping_ratio: float
    vehicle_length_m: float
    bogie_semi_wheelbase_m: float
    bogie_centre_distance_m: float
    traffic_share: float
    vehicles_min: int
    vehicles_max: int
    speed_mean_mps: float
    speed_sd_mps: float
    speed_min_mps: float
    speed_max_mps: float
    squeal_mode_hz: float
    squeal_modal_mass_kg: float
    squeal_damping_ratio: float
    wheel_radiating_area_m2: float
    squeal_radiation_efficiency: float

    @property
    def mean_vehicles(self) -> float:
        """Vehicles of a consist of the mean length (vehicles_min to vehicles_max) [-]."""
        return (self.vehicles_min + self.vehicles_max) / 2

    @property
    def mean_axles_per_train(self) -> float:
        """Axles of a consist of the mean length [-]."""
        return self.axles_per_vehicle * self.mean_vehicles


@dataclass(frozen=True)
class WheelRailContact:
    """Materials, transverse radii and creep curves of the wheel-rail contact (units as in CONTACT_SPECS;
    creep.dry.k1 is creep_dry_k1), and creep(friction_state), the creep curve of each pass."""

    young_modulus_pa: float
    poisson_ratio: float
    rail_head_radius_m: float
    wheel_transverse_radius_m: float
    k3_convention: str
    creep_reduction_factor: float
    k3_n: float
    creep_dry_k1: float
    creep_dry_k2: float
    creep_wet_k1: float
    creep_wet_k2: float
    creep_friction_modifier_k1: float
    creep_friction_modifier_k2: float
    creep_contaminated_k1: float
    creep_contaminated_k2: float

    def creep(self, friction_state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """k1, k2 [-] per pass for TrainPass.FRICTION_* values (NaN for an unknown value)."""
        k1 = np.full(np.shape(friction_state), np.nan)
        k2 = np.full(np.shape(friction_state), np.nan)
        for code, name in FRICTION_NAMES.items():
            sel = np.asarray(friction_state) == code
            k1[sel], k2[sel] = getattr(self, f"creep_{name}_k1"), getattr(self, f"creep_{name}_k2")
        return k1, k2


@dataclass(frozen=True)
class Site:
    """A wayside site: identity, curve, wheel-rail contact and rolling-stock table."""

    site_id: str
    curve_radius_m: float
    vehicles: Mapping[str, VehicleClass]
    contact: WheelRailContact = field(default_factory=lambda: values_of(WheelRailContact,
                                                                        {s.name: s.default for s in CONTACT_SPECS}))
    track: Track = field(default_factory=Track)
    time_zone: str = "UTC"

    def contact_patch(self, wheel_radius_m: np.ndarray | float, load_n: np.ndarray | float) -> hertz.HertzContact:
        """Hertz contact of a wheel of rolling radius [m] on the straight rail head under load [N]
        (semi-axis a along the rail)."""
        c = self.contact
        return hertz.contact_ellipse(wheel_radius_m, c.wheel_transverse_radius_m, np.inf, c.rail_head_radius_m,
                                     hertz.contact_modulus(c.young_modulus_pa, c.poisson_ratio), load_n)

    @property
    def mean_axles_per_train(self) -> float:
        """Axles per train over the rolling-stock table, weighted by the classes' traffic shares
        (equally when every share is 0) [-]."""
        vs = list(self.vehicles.values())
        share = np.array([v.traffic_share for v in vs])
        w = share / share.sum() if share.sum() > 0 else np.full(len(vs), 1.0 / len(vs))
        return float(w @ np.array([v.mean_axles_per_train for v in vs]))

    def per_pass(self, vehicle_class: Any, attribute: str) -> np.ndarray:
        """A rolling-stock column per pass: the VehicleClass attribute of each pass's class name."""
        column = {name: getattr(v, attribute) for name, v in self.vehicles.items()}
        return np.array(list(map(column.__getitem__, vehicle_class)))  # map: no bytecode loop per pass

    def vehicle(self, name: str) -> VehicleClass:
        """The vehicle class called name, or a ConfigError listing the known ones."""
        try:
            return self.vehicles[name]
        except KeyError:
            raise ConfigError(f"unknown vehicle class {name!r}; the site knows {sorted(self.vehicles)}") from None


def site_from_values(values: Mapping[str, Any]) -> Site:
    """Build a Site from flat dotted parameter values (a parameter file or a node's parameters)."""
    top = resolve(SITE_SPECS, values)
    vehicles = {}
    for name in top["vehicle_classes"]:
        prefix = f"vehicle.{name}."
        v = VehicleClass(name=name, **resolve(VEHICLE_SPECS, section(values, prefix), where=prefix, strict=True))
        if v.vehicles_min > v.vehicles_max or v.speed_min_mps > v.speed_max_mps:
            raise ConfigError(f"vehicle class {name!r}: a minimum exceeds its maximum (vehicles or speed)")
        if v.bogie_centre_distance_m + 2.0 * v.bogie_semi_wheelbase_m > v.vehicle_length_m:
            raise ConfigError(f"vehicle class {name!r}: bogie_centre_distance_m + 2 bogie_semi_wheelbase_m exceeds "
                              "vehicle_length_m (the axles must lie on the vehicle)")
        vehicles[name] = v
    if not vehicles:
        raise ConfigError("parameter 'vehicle_classes' names no vehicle class")
    time_zone(top["time_zone"])
    return Site(site_id=top["site_id"], curve_radius_m=top["curve_radius_m"], vehicles=vehicles,
                time_zone=top["time_zone"],
                contact=values_of(WheelRailContact, resolve(CONTACT_SPECS, section(values, "contact."), "contact.",
                                                            strict=True)),
                track=Track(**resolve(TRACK_SPECS, section(values, "track."), "track.", strict=True)))
