"""What the site's noise models know of each vehicle class before any pass: wheel roughness,
contact filter, transfers, traction, all speed-independent and built once per site (the
mechanics transfers and the wheel modes kept in the on-disk cache, core.cache)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from rail_monitor.core.cache import cached_arrays
from rail_monitor.core.site import Site, VehicleClass
from rail_monitor.models import cnossos as cn
from rail_monitor.models import cnossos_directivity as cdir
from rail_monitor.models import cnossos_roughness as crough
from rail_monitor.models import cnossos_tables as ct
from rail_monitor.models import cnossos_transfer as xfer
from rail_monitor.models import wheel_modes as wm
from rail_monitor.models import wheel_rail_noise as wrn
from rail_monitor.models.track import Track
from rail_monitor.noise.config import NoiseConfig


def source_component(kind: str, source: str) -> str:
    """The component name of a CNOSSOS-EU source radiated at height A or B (traction_a, ...)."""
    return f"{kind}_{source.lower()}"


# CNOSSOS-EU's components radiated from source B (4 m above the rail head); the others from A.
SOURCE_B_COMPONENTS = tuple(source_component(kind, "B") for kind in ("traction", "aerodynamic"))
AERODYNAMIC_COMPONENTS = tuple(source_component("aerodynamic", s) for s in cdir.SOURCE_HEIGHTS)


@dataclass(frozen=True)
class ClassTerms:
    """Per vehicle class, speed-independent: wheel roughness, filters and transfers."""

    wheel_db: np.ndarray                 # on the CNOSSOS wavelength grid [dB re 1 um]
    a3_db: np.ndarray                    # CNOSSOS contact filter on the grid [dB]
    a3_patch_m: float                    # Hertz semi-length along the rail of A3's table entry [m]
    cnossos: dict[str, np.ndarray]       # L_H per component [dB per axle], 24 bands
    mechanics: dict[str, np.ndarray]     # L_H,mech per component [dB per axle]
    traction: dict[str, np.ndarray]      # CNOSSOS L_W,0 per vehicle by source [dB re 1 pW], 24 bands


def class_terms(site: Site, cfg: NoiseConfig, tables: ct.Tables, track_db: np.ndarray, rolling_excess_db: float,
                bridge_db: np.ndarray | None) -> dict[str, ClassTerms]:
    """Every class's terms. rolling_excess_db: added to every CNOSSOS-EU rolling transfer (the
    curve-squeal term and the 2015 bridge constant); bridge_db: Table G-7's transfer or None."""
    out = {}
    for name, v in site.vehicles.items():
        traction = {} if v.traction == "none" else {
            source_component("traction", src): cn.traction_sound_power(v.traction, src, "constant", tables)
            for src in cdir.SOURCE_HEIGHTS}
        contact = site.contact_patch(v.wheel_diameter_m / 2.0, v.wheel_load_n)
        (a3_load, a3_diameter), a3 = crough.contact_filter(v.wheel_load_n, v.wheel_diameter_m, tables)
        _, veh = xfer.vehicle_transfer(v.wheel_diameter_m, tables)
        cnossos = {"track": track_db + rolling_excess_db, "vehicle": veh + rolling_excess_db}
        if v.freight:  # L_H,VEH,SUP of Table G-3c: 0 dB, for freight vehicles only (eq. 2.3.9)
            cnossos["superstructure"] = np.full(len(tables.band), rolling_excess_db)
        if bridge_db is not None:
            cnossos["bridge"] = bridge_db
        mech = mechanics_transfer(tables.band, site.track, v, float(contact.stiffness), cfg)
        a3_patch = float(site.contact_patch(a3_diameter / 2.0, a3_load).a)
        out[name] = ClassTerms(crough.wheel_roughness(v.brake_type, cfg.interpolation, tables), a3, a3_patch, cnossos,
                               mech, traction)
    return out


def mechanics_transfer(band: np.ndarray, trk: Track, v: VehicleClass, contact_stiffness_npm: float,
                       cfg: NoiseConfig) -> dict[str, np.ndarray]:
    """The mechanics model's L_H,mech per component for an axle of the class (models.wheel_rail_noise.
    axle_transfer), kept in the on-disk cache: 0.2 s a class at 400 frequencies per band, most of it
    the wheel modes' radiation efficiencies, paid at every node start and command otherwise."""
    inputs = {"band": np.asarray(band).tolist(), "track": dataclasses.asdict(trk),
              "unsprung_mass_kg": v.unsprung_mass_kg, "contact_stiffness_npm": contact_stiffness_npm,
              "wheel_diameter_m": v.wheel_diameter_m, "radiators": dataclasses.asdict(cfg.radiators),
              "points": cfg.transfer_points, "wheel": cfg.wheel, "wheel_damping_ratio": v.wheel_damping_ratio}

    def build() -> dict[str, np.ndarray]:
        modes = wheel_modes(v.wheel_diameter_m) if cfg.wheel == "modal" else None
        return wrn.axle_transfer(band, trk, v.unsprung_mass_kg, contact_stiffness_npm, v.wheel_diameter_m,
                                 cfg.radiators, cfg.transfer_points, modes=modes,
                                 wheel_damping_ratio=v.wheel_damping_ratio)

    arrays = cached_arrays("axle_transfer", inputs, build)
    return {name: arrays[name] for name in wrn.COMPONENTS}


def wheel_modes(diameter_m: float) -> wm.WheelModes:
    """The flexible modes of the representative wheel of this diameter (models.wheel_modes), kept in
    the on-disk cache: their finite-element solution takes about 0.6 s per wheel."""
    section = wm.WheelSection.scaled(diameter_m)
    arrays = cached_arrays("wheel_modes", dataclasses.asdict(section), lambda: wm.wheel_modes(section).arrays())
    return wm.WheelModes(*(np.array(arrays[k]) for k in wm.MODE_ARRAYS), section.rolling_radius_m)
