"""The site's rolling-noise parameters: source model, interpolation rule, baseline rail roughness,
CNOSSOS-EU track terms, receiver and ground, mechanics radiators."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, resolve, section, values_of
from rail_monitor.models import cnossos_bands as cb
from rail_monitor.models import cnossos_roughness as crough
from rail_monitor.models import cnossos_tables as ct
from rail_monitor.models import cnossos_transfer as xfer
from rail_monitor.models import wheel_rail_noise as wrn
from rail_monitor.models.cnossos_catalogue import with_catalogue
from rail_monitor.models.passby import Receiver

if TYPE_CHECKING:
    from rail_monitor.core.site import Site

MODELS = ("cnossos", "mechanics")
PASS_BY_SOURCES = ("axles", "line")
CONTACT_FILTERS = ("hertz_line", "cnossos")
ROUGHNESS_SOURCES = ("E", "M", "measured")
_CLASS_E = crough.rail_roughness("E")

NOISE_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("model", "cnossos", "Source model of noise/rolling: CNOSSOS-EU (Directive 2015/996 as amended by "
              "2021/1226), the mechanics model, or both (one message per model).", choices=(*MODELS, "both")),
    ParamSpec("cnossos_edition", ct.DEFAULT_EDITION, "Edition of CNOSSOS-EU's Appendix G: 2021 (Directive 2015/996 "
              "as amended by 2021/1226, in force) or 2015 (the 2015 text at the precision of the European Commission's "
              "reference module: its scalar bridge constant, absolute vertical directivity, 920 mm contact filter).",
              choices=ct.EDITIONS),
    ParamSpec("interpolation", "reference", "Wavelength-to-frequency rule: the European reference module's (each "
              "table mapped on its own, dB linear in wavelength, ends held) or NoiseModelling's (energy linear in lg f "
              "on its grid, joints before the contact filter).", choices=cb.INTERPOLATION_RULES),
    ParamSpec("rail_roughness", "E", "Baseline rail roughness: class E (EN ISO 3095:2013), class M (CNOSSOS "
              "average network) or the measured spectrum below.", choices=ROUGHNESS_SOURCES),
    ParamSpec("rail_roughness_wavelength_m", ct.tables().wavelength_m.tolist(), "Wavelengths of the measured "
              "rail roughness, ascending [m] (default: the CNOSSOS grid).", 1e-4, 10.0),
    ParamSpec("rail_roughness_db", _CLASS_E.tolist(), "Measured rail roughness per 1/3-octave wavelength band "
              "[dB re 1 um] (default: class E).", -60.0, 80.0),
    ParamSpec("cnossos_catalogue", "", "A catalogue of your own added to the edition's CNOSSOS-EU tables: the text "
              "of one or more tables in the package's CSV format (docs/models.md), first column frequency_hz "
              "(track_<name>, vehicle_wheel_<d>mm, traction_<type>_<constant|idling>_<A|B>) or wavelength_mm on the "
              "edition's grid (contact_filter_<load>kN_<d>mm); rail-monitor site --cnossos-catalogue FILE puts a "
              "file here."),
    ParamSpec("track_transfer", "", "Track transfer column to use (a track_<name> of the tables or the catalogue); "
              "'': by sleeper_type and the pad class."),
    ParamSpec("sleeper_type", "monoblock", "Sleeper type for CNOSSOS's track transfer (Table G-3a); the pad class "
              "follows track.pad_stiffness_npm.", choices=xfer.SLEEPER_TYPES),
    ParamSpec("bridge", "none", "Bridge at the site (CNOSSOS Table G-7; edition 2021).", choices=xfer.BRIDGE_TYPES),
    ParamSpec("bridge_constant_db", 0.0, "Edition 2015's bridge constant C_bridge, added to the rolling noise [dB]; "
              "0: no bridge.", 0.0, 30.0),
    ParamSpec("joints_per_100m", 0.0, "Rail joints (impact noise, CNOSSOS Table G-4) per 100 m [-]; 0: none.",
              0.0, 100.0),
    ParamSpec("curve_squeal", False, "Add CNOSSOS's curve-squeal term (+8 dB R <= 300 m, +5 dB to 500 m) to the "
              "CNOSSOS rolling noise. Off: squeal is squeal_risk_model's, noise/squeal."),
    ParamSpec("aerodynamic", False, "Add CNOSSOS-EU's aerodynamic noise (Table G-6, sources A and B) to the CNOSSOS "
              "prediction of passes above 200 km/h."),
    ParamSpec("receiver_distance_m", 7.5, "Horizontal distance of the receiver from the track centre [m].",
              0.5, 1000.0),
    ParamSpec("receiver_height_m", 1.2, "Receiver height above the rail head [m].", -10.0, 100.0),
    ParamSpec("source_height_m", 0.5, "Height of the rolling-noise source line above the rail head [m] "
              "(CNOSSOS-EU source A, h = 1: 0.5 m, Directive 2015/996 Annex II 2.3.1).", 0.0, 5.0),
    ParamSpec("pass_by_sources", "axles", "Sources of the pass-by levels: a moving point source per axle (ISO 3095's "
              "moving train: LpAFmax sees the bogies) or a uniform line source of the train's length (about 1.2 dB "
              "lower LpAFmax, the same TEL; a batch about 1.5x faster).", choices=PASS_BY_SOURCES),
    ParamSpec("ground_reflection", 1.0, "Energy reflection coefficient of the ground [-] (1: hard, 0: free "
              "field).", 0.0, 1.0),
    ParamSpec("ground_flow_resistivity_kpa_s_m2", 0.0, "Flow resistivity of a porous ground [kPa s/m2]: the image "
              "path then weighs |Q|^2 per band, Q the spherical-wave reflection coefficient with Delany-Bazley's "
              "impedance (about 200: grass-covered soil; 20-80: loose ballast); 0: ground_reflection instead.",
              0.0, 1.0e6),
    ParamSpec("ground_depth_m", 0.0, "Depth of the reflecting ground plane below the rail head [m].", 0.0, 10.0),
    ParamSpec("rail_radius_m", float(wrn.Radiators.rail_radius_m), "Mechanics: radius of the cylinder radiating "
              "like the rail's vertical motion [m].", 0.01, 1.0),
    ParamSpec("sleeper_area_m2", wrn.Radiators.sleeper_area_m2, "Mechanics: radiating top area of a half sleeper "
              "[m2].", 0.0, 5.0),
    ParamSpec("wheel_rim_width_m", wrn.Radiators.wheel_rim_width_m, "Mechanics: wheel rim width [m].", 0.01, 0.5),
    ParamSpec("contact_filter", "cnossos", "Mechanics: the contact filter. cnossos: CNOSSOS-EU's A3 (Table G-2, "
              "the nearest wheel-load and diameter entry) read at the pass's own contact length, a 2-D filter of "
              "roughness not correlated across the contact; hertz_line: averaging over the Hertzian contact length of "
              "roughness fully correlated across the contact (1-D).", choices=CONTACT_FILTERS),
    ParamSpec("band_points", 5, "Mechanics: frequencies per 1/3-octave band for the contact filter's band "
              "average per pass [-].", 1, 50),
    ParamSpec("transfer_points", 400, "Mechanics: frequencies per 1/3-octave band for the speed-independent "
              "transfers, resolving the wheel's resonances (400 converge to 0.3 dB) [-].", 5, 5000),
    ParamSpec("wheel", "modal", "Mechanics: the wheel as its unsprung mass plus its flexible modes (axisymmetric "
              "finite elements of the class's wheel diameter) or as a rigid mass.", choices=("modal", "rigid")),
)


# What a consumer of noise/rolling must know of it: the models published and the receiver.
PREDICTED_SPECS = tuple(s for s in NOISE_SPECS if s.name in ("model", "receiver_distance_m", "receiver_height_m"))


def selected_models(model: str) -> tuple[str, ...]:
    """The source models a ``noise.model`` value selects."""
    return MODELS if model == "both" else (model,)


def band_centres_hz() -> np.ndarray:
    """The nominal 1/3-octave band centres every noise prediction is given on [Hz]."""
    return ct.tables().band_hz


@dataclass(frozen=True)
class NoiseConfig:
    """The site's noise parameters (names and units as in NOISE_SPECS), with the receiver and the mechanics
    model's radiators they describe."""

    model: str
    cnossos_edition: str
    interpolation: str
    rail_roughness: str
    rail_roughness_wavelength_m: list[float]
    rail_roughness_db: list[float]
    cnossos_catalogue: str
    track_transfer: str
    sleeper_type: str
    bridge: str
    bridge_constant_db: float
    joints_per_100m: float
    curve_squeal: bool
    aerodynamic: bool
    receiver_distance_m: float
    receiver_height_m: float
    source_height_m: float
    pass_by_sources: str
    ground_reflection: float
    ground_flow_resistivity_kpa_s_m2: float
    ground_depth_m: float
    rail_radius_m: float
    sleeper_area_m2: float
    wheel_rim_width_m: float
    contact_filter: str
    band_points: int
    transfer_points: int
    wheel: str

    @property
    def receiver(self) -> Receiver:
        return Receiver(self.receiver_distance_m, self.receiver_height_m, self.source_height_m, self.ground_depth_m,
                        self.ground_reflection, 1.0e3 * self.ground_flow_resistivity_kpa_s_m2)

    @property
    def radiators(self) -> wrn.Radiators:
        """The mechanics model's rail, sleeper and wheel radiators."""
        return wrn.Radiators(self.rail_radius_m, self.sleeper_area_m2, self.wheel_rim_width_m)


def noise_config(values: Mapping[str, Any], prefix: str = "noise.") -> NoiseConfig:
    """Checked noise parameters from flat parameter values (keys under prefix)."""
    values = resolve(NOISE_SPECS, section(values, prefix), where=prefix, strict=True)
    wl, db = values["rail_roughness_wavelength_m"], values["rail_roughness_db"]
    if len(wl) != len(db) or len(wl) < 2 or np.any(np.diff(wl) <= 0):
        raise ConfigError(f"parameters '{prefix}rail_roughness_wavelength_m' and '{prefix}rail_roughness_db' must "
                          "have the same length (at least 2), wavelengths strictly ascending")
    _check_edition_terms(values, prefix)
    _check_catalogue(values, prefix)
    return values_of(NoiseConfig, values)


def site_tables(edition: str, catalogue: str) -> ct.Tables:
    """The CNOSSOS-EU tables a site selects: its edition's, with its catalogue."""
    return with_catalogue(ct.tables(edition), catalogue)


def check_traction(site: Site, cfg: NoiseConfig) -> ct.Tables:
    """ConfigError for a vehicle class whose traction type the site's tables lack; the tables."""
    tables = site_tables(cfg.cnossos_edition, cfg.cnossos_catalogue)
    for name, v in site.vehicles.items():
        if v.traction != "none" and v.traction not in tables.traction_types:
            raise ConfigError(f"parameter 'vehicle.{name}.traction': CNOSSOS-EU edition {cfg.cnossos_edition} has no "
                              f"traction type {v.traction!r} (it has {', '.join(tables.traction_types)}; a site's "
                              "catalogue may add more)")
    return tables


def _check_catalogue(values: Mapping[str, Any], prefix: str) -> None:
    """The user's catalogue must read against its edition, and a chosen track transfer must exist."""
    try:
        tables = site_tables(values["cnossos_edition"], values["cnossos_catalogue"])
    except ValueError as exc:
        raise ConfigError(f"parameter '{prefix}cnossos_catalogue': {exc}") from None
    name = values["track_transfer"]
    if name and (not name.startswith("track_") or name not in tables.by_frequency):
        known = ", ".join(n for n in tables.by_frequency if n.startswith("track_"))
        raise ConfigError(f"parameter '{prefix}track_transfer' = {name!r} is none of the edition's and the "
                          f"catalogue's track transfers ({known})")


def _check_edition_terms(values: Mapping[str, Any], prefix: str) -> None:
    """Terms the chosen CNOSSOS-EU edition does not have are refused, not silently replaced."""
    edition = values["cnossos_edition"]
    refusals = {
        "2015": [("bridge", values["bridge"] != "none", "has a bridge constant instead of Table G-7: set "
                  f"'{prefix}bridge_constant_db'"),
                 ("sleeper_type", values["sleeper_type"] == "direct_fastening", "has no direct-fastening track "
                  "transfer"),
                 ("interpolation", values["interpolation"] == "noisemodelling", "is not read by NoiseModelling's "
                  "rule (its grid is the 2021 tables')")],
        "2021": [("bridge_constant_db", values["bridge_constant_db"] != 0.0, "has Table G-7 instead of a bridge "
                  f"constant: set '{prefix}bridge'")],
    }
    for name, refused, why in refusals[edition]:
        if refused:
            raise ConfigError(f"parameter '{prefix}{name}': CNOSSOS-EU edition {edition} {why}")
