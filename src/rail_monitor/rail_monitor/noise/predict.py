"""Rolling noise at a site: its noise parameters and the prediction for each train pass.

Glue between the pass table, the site (track, contact, rolling stock), the corrugation state and
the two source models: :mod:`rail_monitor.models.cnossos` (the EU method, default) and
:mod:`rail_monitor.models.wheel_rail_noise` (mechanics, sharing :mod:`rail_monitor.models.track`
with the corrugation model, so pad stiffness and corrugation change the noise for mechanical
reasons). Both share one roughness input and one propagation (:mod:`rail_monitor.models.passby`).

Roughness. The rail roughness is the site's baseline (ISO 3095 class E, CNOSSOS class M, or a
measured spectrum in dB re 1 um on 1/3-octave wavelength bands): the rail as ground, without
corrugation. The corrugation state adds, in energy, its growth since grinding in each of its
bands (its r.m.s. amplitude squared minus its post-grinding amplitude squared, at the nearest
baseline wavelength within 1/6 octave), so a freshly ground state is the baseline itself and a
measured baseline is not counted twice. The increase since grinding is LpAeq,Tp with the current
state minus that on the baseline (INCREASE_REFERENCE). The wheel roughness is CNOSSOS-EU's, per brake type.

Per pass: the class's wheel (diameter; the transfers use the Hertz contact stiffness at its nominal
load, tabulated per class; the mechanics model's contact filter takes the pass's own Hertz patch,
from its wheel and load as in its contact state; CNOSSOS's is the Directive's table for the class's
nominal load and diameter), axles, length and speed from the pass (class defaults filled). Sound
power per metre of train: L_W' = L_R,TOT + L_H + 10 lg(axles / length) per band.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Sequence

import numpy as np

from rail_monitor.core.contact import wheel_radius
from rail_monitor.core.passes import KMH_PER_MPS, PassTable
from rail_monitor.core.site import Site
from rail_monitor.models import cnossos as cn
from rail_monitor.models import cnossos_bands as cb
from rail_monitor.models import cnossos_directivity as cdir
from rail_monitor.models import cnossos_roughness as crough
from rail_monitor.models import cnossos_transfer as xfer
from rail_monitor.models import wheel_rail_noise as wrn
from rail_monitor.models.axle_layout import AxleLayout, axle_layout
from rail_monitor.models.levels import level, power
from rail_monitor.models.passby import pass_by_levels, pass_geometry
from rail_monitor.models.passby_paths import (
    BandPaths,
    PassGeometry,
    a_weighted_paths,
    f_weighted_peaks,
    lpaeq_weights,
    power_paths,
)
from rail_monitor.noise.class_terms import (
    AERODYNAMIC_COMPONENTS,
    SOURCE_B_COMPONENTS,
    ClassTerms,
    class_terms,
    source_component,
)
from rail_monitor.noise.config import MODELS, NoiseConfig, check_traction, selected_models
from rail_monitor.noise.records import Corrugation, NoisePrediction

# What roughness_growth_increase_db is measured against, for every label that shows it.
INCREASE_REFERENCE = ("the same pass on the site's baseline rail roughness (noise.rail_roughness: as ground, "
                      "no corrugation)")


def roughness_power(amplitude_m: np.ndarray) -> np.ndarray:
    """Squared roughness re (1 um)^2 [-] of an r.m.s. amplitude [m] (10 lg of it: dB re 1 um)."""
    return (np.asarray(amplitude_m, float) / 1e-6) ** 2


class RollingNoiseModel:
    """Both source models for one site, with everything speed-independent computed once."""

    def __init__(self, site: Site, cfg: NoiseConfig, engine: str = "numpy") -> None:
        self.site, self.cfg, self.engine = site, cfg, engine
        self.edition = ed = cfg.cnossos_edition
        self.tables = t = check_traction(site, cfg)
        self.grid = t.wavelength_m
        self.band, self.band_hz = t.band, t.band_hz
        self.receiver = cfg.receiver
        (_, psi), _ = self.receiver.paths()
        self.vertical_db = cdir.vertical_directivity_a_db(psi, self.band_hz, ed)
        self.vertical_gain = power(self.vertical_db)
        self.baseline_db = self._baseline()
        self.impact_db = crough.impact_roughness(cfg.joints_per_100m / 100.0, t) if cfg.joints_per_100m > 0 else None
        if cfg.track_transfer:
            self.track_name, track_db = cfg.track_transfer, t.by_frequency[cfg.track_transfer]
        else:
            self.track_name, track_db = xfer.track_transfer(cfg.sleeper_type, site.track.pad_stiffness_npm, t)
        self.bridge_db = xfer.bridge_transfer(cfg.bridge, t)
        # The curve-squeal term and the 2015 bridge constant raise every rolling component alike.
        excess = (cn.curve_squeal_db(site.curve_radius_m) if cfg.curve_squeal else 0.0) + cfg.bridge_constant_db
        self.receiver_b = dataclasses.replace(self.receiver, source_height_m=cdir.SOURCE_HEIGHTS["B"])
        self.classes = class_terms(site, cfg, t, track_db, excess, self.bridge_db)

    def component_names(self, model: str) -> list[str]:
        """The model's source components over the site's classes, in a fixed order."""
        names: dict[str, None] = {}
        for terms in self.classes.values():
            names.update(dict.fromkeys(terms.cnossos if model == "cnossos" else terms.mechanics))
        if model == "cnossos":
            for terms in self.classes.values():
                names.update(dict.fromkeys(terms.traction))
            if self.cfg.aerodynamic:
                names.update(dict.fromkeys(AERODYNAMIC_COMPONENTS))
        return list(names)

    @property
    def models(self) -> tuple[str, ...]:
        """The source models the site's ``noise.model`` selects."""
        return selected_models(self.cfg.model)

    def _baseline(self) -> np.ndarray:
        source = self.cfg.rail_roughness
        if source != "measured":
            return crough.rail_roughness(source, self.tables)
        wl = np.asarray(self.cfg.rail_roughness_wavelength_m, float)
        return np.interp(self.grid, wl, np.asarray(self.cfg.rail_roughness_db, float))

    def rail_roughness_db(self, corrugation: Corrugation | None = None) -> np.ndarray:
        """Rail roughness on the CNOSSOS wavelength grid [dB re 1 um]: the baseline plus, in energy,
        the corrugation state's growth since grinding (module docstring); (grid,) or, for a state
        per pass, (passes, grid)."""
        if corrugation is None:
            return self.baseline_db
        wl = np.asarray(corrugation.wavelength_m, float)
        if not len(wl):
            return self.baseline_db
        octaves = np.abs(np.log2(self.grid[:, None] / wl[None, :]))
        nearest = np.argmin(octaves, axis=1)
        inside = octaves[np.arange(len(self.grid)), nearest] <= 1.0 / 6.0
        grown = np.maximum(roughness_power(corrugation.amplitude_m) - roughness_power(corrugation.post_grinding_m),
                           0.0)
        extra = np.where(inside, grown[..., nearest], 0.0)
        return level(power(self.baseline_db) + extra)

    def rail_share(self, passes: PassTable, corrugation: Corrugation | None = None) -> np.ndarray:
        """The rail's share of the combined effective roughness energy per pass and band (N, B)
        [-]: CNOSSOS's tables read at lambda = v / f (each mapped on its own, the ``reference``
        rule), joints' impact roughness counted with the rail; the contact filter acts on both
        alike, so it cancels. ``passes`` valid with class defaults filled."""
        rail = self.rail_roughness_db(corrugation)
        out = np.empty((len(passes), len(self.band)))
        for name, rows in passes.class_groups:
            speed = passes.speed_mps[rows]
            def at(table: np.ndarray, speed: np.ndarray = speed) -> np.ndarray:
                return power(cb.at_band_frequencies(table, speed, self.band_hz, edition=self.edition))

            on_rail = at(rail if rail.ndim == 1 else rail[rows])
            if self.impact_db is not None:
                on_rail = on_rail + at(self.impact_db)
            wheel = at(self.classes[name].wheel_db)
            out[rows] = on_rail / (on_rail + wheel)
        return out

    def predict(self, passes: PassTable, model: str | None = None,
                corrugation: Corrugation | None = None) -> NoisePrediction:
        """RollingNoise fields per pass of one model (default: the first of the site's
        ``noise.model``): predict_models of it alone."""
        model = model or self.models[0]
        return self.predict_models(passes, (model,), corrugation)[model]

    def predict_models(self, passes: PassTable, models: Sequence[str] = (),
                       corrugation: Corrugation | None = None) -> dict[str, NoisePrediction]:
        """RollingNoise fields per pass (arrays over passes; bands last) of each model (default: the
        site's ``noise.model``), vectorised; the passes' geometry and the time histories of their
        axles are computed once for all the models.

        ``passes`` must be valid for the site with class defaults filled.
        """
        models = tuple(models) or self.models
        if unknown := [m for m in models if m not in MODELS]:
            raise ValueError(f"unknown noise model {unknown[0]!r}; use one of {MODELS}")
        geometry = self._geometries(passes, models)
        weights = self._lpaeq_weights(geometry)
        rail = self.rail_roughness_db(corrugation)
        # A rail per pass read at the bands once for every model (one spectrum is cached where read).
        rail_power = (cb.power_at_bands(rail, passes.speed_mps, self.band_hz, self.edition)
                      if rail.ndim == 2 and self.cfg.interpolation == "reference" else None)
        out, paths = {}, []
        for model in models:
            filter_db = self._filter_db(passes, model)
            roughness, components = self._sources(rail, passes, model, filter_db, rail_power)
            lines = self._paths(components, geometry)
            pb = pass_by_levels(geometry[0], lines)
            paths.append(a_weighted_paths(geometry[0], lines))
            names = list(components)
            growth = np.zeros(len(passes))
            if corrugation is not None:
                growth = pb.lpaeq_tp_dba - self._baseline_lpaeq(passes, model, filter_db, components, weights)
            out[model] = NoisePrediction(
                model=model, band_centre_hz=self.band_hz, component_names=names, speed_mps=passes.speed_mps,
                lp_db=pb.lp_db, lw_db=level(sum(components.values())), roughness_db=roughness,
                pass_by_time_s=pb.pass_by_time_s,
                lpaeq_tp_dba=pb.lpaeq_tp_dba, lpafmax_dba=pb.lpafmax_dba, tel_dba=pb.tel_dba,
                component_lpaeq_dba=np.stack([self._lpaeq({c: components[c]}, weights) for c in names], axis=-1),
                roughness_growth_increase_db=growth)
        peaks = level(f_weighted_peaks(geometry[0], paths, self.engine))
        return {m: dataclasses.replace(p, lpafmax_dba=peak) for (m, p), peak in zip(out.items(), peaks, strict=True)}

    def vehicle_sound_power(self, passes: PassTable, model: str,
                            corrugation: Corrugation | None = None) -> dict[str, np.ndarray]:
        """L_W,0 per vehicle [dB re 1 pW] per source component (passes x bands): the power per
        metre of train times the vehicle length (train length / vehicles); for CNOSSOS-EU the
        Directive's L_W,0 of eqs. 2.3.7-2.3.9 and 2.3.14, to compare with another implementation."""
        _, components = self._sources(self.rail_roughness_db(corrugation), passes, model,
                                      self._filter_db(passes, model))
        per_vehicle = (passes.train_length_m / passes.vehicle_count)[:, None]
        return {c: level(w * per_vehicle) for c, w in components.items()}

    def _axles(self, passes: PassTable) -> AxleLayout:
        """The axles of each pass's train (a point source each): its counts and length, the class's
        bogies scaled to the pass's vehicle pitch."""
        per = self.site.per_pass
        ratio = per(passes.vehicle_class, "bogie_centre_distance_m") / per(passes.vehicle_class, "vehicle_length_m")
        return axle_layout(passes.train_length_m, passes.vehicle_count, passes.axle_count, ratio,
                           per(passes.vehicle_class, "bogie_semi_wheelbase_m"))

    def _filter_db(self, passes: PassTable, model: str) -> np.ndarray | None:
        """The mechanics model's contact filter level per pass (passes x bands; its own patch, from
        its wheel load, the same on both rails): the 1-D filter of models.wheel_rail_noise
        (noise.contact_filter: hertz_line) or the class's A3 at the pass's patch (cnossos); None
        for CNOSSOS, whose filter is in its tables."""
        if model == "cnossos":
            return None
        patch = self.site.contact_patch(wheel_radius(self.site, passes.vehicle_class), passes.wheel_load_n)
        patch_a = np.asarray(patch.a)
        if self.cfg.contact_filter == "hertz_line":
            return level(wrn.contact_filter_power(passes.speed_mps, self.band, patch_a, self.cfg.band_points))
        out = np.empty((len(passes), len(self.band)))
        for name, rows in passes.class_groups:
            terms = self.classes[name]
            out[rows] = cb.contact_filter_at_patch(terms.a3_db, passes.speed_mps[rows], terms.a3_patch_m,
                                                   patch_a[rows], self.band_hz, self.cfg.interpolation, self.edition)
        return out

    def _sources(self, rail_db: np.ndarray, passes: PassTable, model: str, filter_db: np.ndarray | None,
                 rail_power: np.ndarray | None = None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Effective roughness [dB re 1 um] and sound power per metre of train per component (power ratio
        re 1 pW/m) (passes x bands) on a rail roughness spectrum. filter_db: the mechanics model's contact
        filter level per pass (None for CNOSSOS); rail_power: the rail's power_at_bands, if at hand."""
        n, nb = len(passes), len(self.band)
        per_metre = (passes.axle_count / passes.train_length_m)[:, None]
        roughness = np.empty((n, nb))
        # Every component of the model, even with no passes (an empty history gives empty arrays);
        # one a class lacks stays 0 (-inf dB) on its passes (NoisePrediction.components).
        components = {c: np.zeros((n, nb)) for c in self.component_names(model)}
        for name, rows, energy, transfers in self._class_roughness(rail_db, passes, model, filter_db, rail_power):
            roughness[rows] = level(energy)
            for comp, lh in transfers.items():
                components[comp][rows] = energy * power(lh) * per_metre[rows]
            if model == "cnossos":
                self._vehicle_sources(components, rows, self.classes[name], passes)
        return roughness, components

    def _class_roughness(self, rail_db: np.ndarray, passes: PassTable, model: str, filter_db: np.ndarray | None,
                         rail_power: np.ndarray | None = None
                         ) -> Iterator[tuple[str, np.ndarray, np.ndarray, dict[str, np.ndarray]]]:
        """(class, its rows, and _roughness's energy and transfers there) per class among the passes."""
        for name, rows in passes.class_groups:
            rail = rail_db if rail_db.ndim == 1 else rail_db[rows]
            yield name, rows, *self._roughness(rail, self.classes[name], passes.speed_mps[rows], model,
                                               None if filter_db is None else filter_db[rows],
                                               None if rail_power is None else rail_power[rows])

    def _vehicle_sources(self, components: dict[str, np.ndarray], rows: np.ndarray, terms: ClassTerms,
                         passes: PassTable) -> None:
        """CNOSSOS-EU's traction and aerodynamic power per metre of train (power ratio re 1 pW/m)
        on the rows of one class: L_W,0 per vehicle times vehicles / train length."""
        per_metre = (passes.vehicle_count[rows] / passes.train_length_m[rows])[:, None]
        for comp, lw0 in terms.traction.items():
            components[comp][rows] = power(lw0) * per_metre
        if self.cfg.aerodynamic:
            speed_kmh = passes.speed_mps[rows] * KMH_PER_MPS
            for src in cdir.SOURCE_HEIGHTS:
                components[source_component("aerodynamic", src)][rows] = \
                    power(cn.aerodynamic_sound_power(speed_kmh, src, self.tables)) * per_metre

    def _geometries(self, passes: PassTable, models: Sequence[str]) -> tuple[PassGeometry, PassGeometry | None]:
        """The pass geometry of source A, and of source B (4 m) where a model has components there."""
        axles = self._axles(passes) if self.cfg.pass_by_sources == "axles" else None
        low = pass_geometry(self.band, passes.train_length_m, passes.speed_mps, self.receiver, axles, self.engine)
        if not {c for m in models for c in self.component_names(m)} & set(SOURCE_B_COMPONENTS):
            return low, None
        return low, pass_geometry(self.band, passes.train_length_m, passes.speed_mps, self.receiver_b, axles,
                                  self.engine)

    def _paths(self, components: dict[str, np.ndarray],
               geometries: tuple[PassGeometry, PassGeometry | None]) -> BandPaths:
        """The band paths of the components (power per metre, power ratios): those of source B as
        a second source line of the same trains (CNOSSOS-EU's horizontal directivity alone), the
        others at source A."""
        geometry, geometry_b = geometries
        low = [w for c, w in components.items() if c not in SOURCE_B_COMPONENTS]
        high = [w for c, w in components.items() if c in SOURCE_B_COMPONENTS]
        total = sum(low) if low else np.zeros_like(high[0])
        return power_paths(total, geometry, self.vertical_gain, (sum(high), geometry_b) if high else None)

    def _lpaeq_weights(self, geometries: tuple[PassGeometry, PassGeometry | None]) -> dict[bool, np.ndarray]:
        """models.passby_paths.lpaeq_weights of source A's line (with the vertical directivity) and of
        source B's where the passes have one, keyed by whether the line is B's."""
        low, high = geometries
        out = {False: lpaeq_weights(low, self.vertical_gain)}
        if high is not None:
            out[True] = lpaeq_weights(high)
        return out

    @staticmethod
    def _lpaeq(components: dict[str, np.ndarray], weights: dict[bool, np.ndarray]) -> np.ndarray:
        """LpAeq,Tp of the components (power ratios) alone [dB(A)] (passes,), by their lines' weights."""
        return level(_weighted(components, weights))

    def _baseline_lpaeq(self, passes: PassTable, model: str, filter_db: np.ndarray | None,
                        components: dict[str, np.ndarray], weights: dict[bool, np.ndarray]) -> np.ndarray:
        """LpAeq,Tp [dB(A)] (passes,) on the baseline rail roughness: the roughness-driven
        components share one effective roughness, so their transfers are summed per source line
        before weighting; the other sources (traction, aerodynamic) are those of ``components``."""
        per_metre, total, rolling = passes.axle_count / passes.train_length_m, np.zeros(len(passes)), set()
        for _, rows, energy, transfers in self._class_roughness(self.baseline_db, passes, model, filter_db):
            lines: dict[bool, np.ndarray] = {}
            for comp, lh in transfers.items():
                on_b = comp in SOURCE_B_COMPONENTS
                lines[on_b] = lines.get(on_b, 0.0) + power(lh)
                rolling.add(comp)
            total[rows] = per_metre[rows] * sum(np.sum(energy * t * weights[b][rows], axis=-1)
                                                for b, t in lines.items())
        others = {c: w for c, w in components.items() if c not in rolling}
        return level(total + _weighted(others, weights))

    def _roughness(self, rail_db: np.ndarray, terms: ClassTerms, speed: np.ndarray, model: str,
                   filter_db: np.ndarray | None, rail_power: np.ndarray | None = None
                   ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Effective roughness at the band frequencies as a power ratio re (1 um)^2 (passes x
        bands) and the transfers [dB]."""
        rule = self.cfg.interpolation
        if model == "cnossos":
            return cb.band_roughness_power(rail_db, terms.wheel_db, terms.a3_db, speed, self.band_hz, rule,
                                           self.impact_db, self.edition, rail_power), terms.cnossos
        if self.cfg.contact_filter == "cnossos":  # each table read on its own, as CNOSSOS-EU's total
            both = cb.band_roughness_power(rail_db, terms.wheel_db, 0.0, speed, self.band_hz, rule, None,
                                           self.edition, rail_power)
            return both * power(filter_db), terms.mechanics
        combined = crough.total_roughness(rail_db, terms.wheel_db, 0.0)
        lr = cb.at_band_frequencies(combined, speed, self.band_hz, rule, self.edition) + filter_db
        return power(lr), terms.mechanics


def _weighted(components: dict[str, np.ndarray], weights: dict[bool, np.ndarray]) -> np.ndarray | float:
    """The sum over components and bands of power times its line's LpAeq weight (passes,)."""
    return sum((np.sum(w * weights[c in SOURCE_B_COMPONENTS], axis=-1) for c, w in components.items()), 0.0)
