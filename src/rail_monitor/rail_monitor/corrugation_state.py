"""Corrugation at a site: roughness per wavelength band, grinding forecast and speed advice.

Glue between the pass table and :mod:`rail_monitor.models.corrugation`, shared by the
``corrugation_estimator`` node, batch mode and ``rail-monitor predict corrugation``.

Each 1/3-octave band is tracked as components at wavelengths spread across it; per axle pass a
component grows by ln Z += ln|1 + K_b F^2 H(V / lambda)| (seed eqs. 1-2 with the contact filter
F), where H uses the site's track (bay-averaged discrete-support receptance), the class's
unsprung mass and the Hertz contact of the class's wheel at its nominal load, and K_b is the
friction state's. A band's r.m.s. is the energy sum of its components, so it tends to grow at the
rate of its fastest one: that rate is the band's g, and the peak g over bands is what the speed
advice minimises. The per-axle growths are tabulated once per site on a 0.1 m/s speed grid and
interpolated linearly.

A pass is identified by (stamp, train_id): a pass already counted, or older than the kept
history, is not counted (so a replay does not grow the state twice), and because ln Z is a sum,
passes give the same state one by one or in a batch.
"""

from __future__ import annotations

import io
import json
import os
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor.errors import ConfigError
from rail_monitor.models import corrugation as cg
from rail_monitor.models import track as tr
from rail_monitor.models.contact_filter import hertzian_line_filter
from rail_monitor.params import ParamSpec, ParamValues, resolve, section
from rail_monitor.passes import FRICTION_NAMES, MAX_SPEED_MPS, PassTable
from rail_monitor.site import Site

NS_PER_DAY = 86_400 * 10**9
SPEED_STEP_MPS = 0.1          # speed grid of the growth tables [m/s]
CHECKPOINT_VERSION = 2
READABLE_VERSIONS = (1, 2)  # 1: before grinding_amplitude (read as the post-grinding default)


class CorruptCheckpoint(ConfigError):
    """A checkpoint file that cannot be read (truncated, failed CRC, missing arrays)."""


def previous_checkpoint(path: str | Path) -> Path:
    """Where save() keeps the checkpoint it replaced: the fallback when the newest is unreadable."""
    path = Path(path)
    return path.with_name(path.name + ".prev")

# K_b per friction state [-/axle pass]. MODELS.md section 2: K_b of order 1e-5 (1 nm of wear per
# pass at 75 kN, k_c = 1.3e9 N/m) for dry rail in partial slip. The wear that drives growth scales
# with frictional power, so lubricated states get less: wet about half, a top-of-rail friction
# modifier (which is sold on less corrugation, e.g. Eadie et al., Wear 265 (2008) 1222-1230) and
# leaf contamination less still. Starting values only: a pair of roughness surveys re-fits them.
K_B_DEFAULTS: dict[str, float] = {"dry": 1.0e-5, "wet": 5.0e-6, "friction_modifier": 3.0e-6, "contaminated": 2.0e-6}

CORRUGATION_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("shortest_wavelength_m", 0.01, "Shortest 1/3-octave wavelength band centre tracked [m].", 0.001, 1.0),
    ParamSpec("longest_wavelength_m", 1.0, "Longest 1/3-octave wavelength band centre tracked [m].", 0.01, 10.0),
    ParamSpec("points_per_band", 5, "Wavelengths across each band over which its growth is averaged [-].", 1, 50),
    *(ParamSpec(f"k_b.{state}", value, f"Wear sensitivity K_b with {state} rail, per axle pass [-] (re-fitted "
                "from roughness surveys).", 0.0, 1.0e-2) for state, value in K_B_DEFAULTS.items()),
    ParamSpec("acceptance_factor", 1.0, "Multiplier on the Grassie et al. (1999) post-grinding acceptance limits "
              "[-].", 0.01, 100.0),
    ParamSpec("intervention_factor", 3.0, "Intervention threshold as a multiple of the acceptance limit [-].",
              1.0, 100.0),
    ParamSpec("post_grinding_fraction", 0.5, "Roughness after grinding as a fraction of the acceptance limit, "
              "when the grinding event gives no spectrum [-].", 0.001, 1.0),
    ParamSpec("lead_time_days", 60.0, "Planning lead time: grinding is due when the forecast is inside it [day].",
              0.0, 3650.0),
    ParamSpec("history_days", 28.0, "Passes kept for the forecast (recent speeds, friction, traffic) and for "
              "duplicate detection; older passes are not counted [day].", 0.01, 3650.0),
    ParamSpec("min_traffic_days", 1.0, "Least span of kept passes from which the traffic rate, and so the "
              "forecast in days, is estimated (a shorter span is biased by the daily timetable) [day].", 0.0, 3650.0),
    ParamSpec("advice_min_speed_mps", 0.0, "Lowest speed the advice may use [m/s] (0: the slowest class "
              "minimum of the rolling-stock table).", 0.0, MAX_SPEED_MPS),
    ParamSpec("advice_max_speed_mps", 0.0, "Highest speed the advice may use [m/s] (0: the line speed, the "
              "highest class maximum).", 0.0, MAX_SPEED_MPS),
    ParamSpec("advice_bin_mps", 0.5, "Width of the speed bins of the advice [m/s].", 0.05, 10.0),
    ParamSpec("advice_max_share", 0.2, "Largest share of traffic the advice puts in one speed bin [-].", 0.01, 1.0),
)


@dataclass(frozen=True)
class CorrugationConfig(ParamValues):
    """The site's corrugation parameters (names and units as in CORRUGATION_SPECS)."""

    @property
    def k_b(self) -> np.ndarray:
        """K_b per friction state, index TrainPass.FRICTION_* - 1 [-/axle pass]."""
        return np.array([self[f"k_b.{name}"] for name in FRICTION_NAMES.values()])


def corrugation_config(values: Mapping[str, Any], prefix: str = "corrugation.") -> CorrugationConfig:
    """Checked corrugation parameters from flat parameter values (keys under prefix)."""
    out = resolve(CORRUGATION_SPECS, section(values, prefix), where=prefix, strict=True)
    if out["shortest_wavelength_m"] >= out["longest_wavelength_m"]:
        raise ConfigError(f"parameter '{prefix}shortest_wavelength_m' must be below '{prefix}longest_wavelength_m'")
    if out["min_traffic_days"] > out["history_days"]:
        raise ConfigError(f"parameter '{prefix}min_traffic_days' exceeds '{prefix}history_days'")
    if out["advice_max_speed_mps"] and out["advice_min_speed_mps"] >= out["advice_max_speed_mps"]:
        raise ConfigError(f"parameter '{prefix}advice_min_speed_mps' must be below '{prefix}advice_max_speed_mps'")
    return CorrugationConfig(out)


@lru_cache(maxsize=8)
def _rail_receptance(track: tr.Track) -> tuple[np.ndarray, np.ndarray]:
    """Bay-averaged discrete-support rail receptance [m/N] on a log frequency grid [Hz]."""
    f = np.geomspace(0.05, 2.0e4, 700)
    return f, tr.bay_averaged_receptance(f, track)


def _interp_log(x: np.ndarray, xp: np.ndarray, yp: np.ndarray) -> np.ndarray:
    """Complex yp(xp) interpolated at x, linearly in ln x (clamped at the ends)."""
    lx, lxp = np.log(np.clip(x, xp[0], xp[-1])), np.log(xp)
    return np.interp(lx, lxp, yp.real) + 1j * np.interp(lx, lxp, yp.imag)


class GrowthTables:
    """Per-axle-pass log growth of each band component, per vehicle class, over the speed grid.

    ``filtered_kernel`` is F^2 H at the components' wavelengths (C, B, V, P); ``set_k_b``
    tabulates ln|1 + K_b F^2 H| (C, 4, B, V, P) for the K_b of each friction state.
    """

    def __init__(self, site: Site, cfg: CorrugationConfig) -> None:
        self.bands = cg.wavelength_bands(cfg["shortest_wavelength_m"], cfg["longest_wavelength_m"])
        self.classes = list(site.vehicles)
        self.speeds = np.arange(1, round(MAX_SPEED_MPS / SPEED_STEP_MPS) + 1) * SPEED_STEP_MPS
        sub = cg.band_sub_wavelengths(self.bands, cfg["points_per_band"])
        f_rail, r_rail = _rail_receptance(site.track)
        kernels = []
        for name in self.classes:
            v = site.vehicle(name)
            patch = site.contact_patch(v.wheel_diameter_m / 2.0, v.wheel_load_n)
            kc, a = float(patch.stiffness), float(patch.a)
            h = cg.growth_kernel(kc, r_rail + tr.wheel_receptance(f_rail, v.unsprung_mass_kg))
            freq = self.speeds[None, :, None] / sub[:, None, :]
            filt = hertzian_line_filter(sub, a)[:, None, :]
            kernels.append(filt * filt * _interp_log(freq, f_rail, h))
        self.filtered_kernel = np.stack(kernels)          # (C, B, V, P)
        self.table = np.empty(0)
        self.k_b = np.full(4, np.nan)

    def set_k_b(self, k_b: np.ndarray) -> None:
        """Tabulate the growth for K_b per friction state (4,) [-/axle pass]."""
        self.k_b = np.asarray(k_b, float).copy()
        self.table = np.stack([cg.filtered_log_growth(kb, self.filtered_kernel, 1.0) for kb in self.k_b], axis=1)

    def class_index(self, names: np.ndarray) -> np.ndarray:
        lookup = {n: i for i, n in enumerate(self.classes)}
        return np.array([lookup[n] for n in names], dtype=np.int64)

    def at(self, class_idx: np.ndarray, friction: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """Per-axle-pass log growth (N, B, P) for passes of class index, friction state (1-4), speed [m/s]."""
        x = np.clip(np.asarray(speed, float) / SPEED_STEP_MPS - 1.0, 0.0, len(self.speeds) - 1.0)
        j = np.minimum(x.astype(np.int64), len(self.speeds) - 2)
        w = (x - j)[:, None, None]
        fi = np.asarray(friction, np.int64) - 1
        return (1.0 - w) * self.table[class_idx, fi, :, j, :] + w * self.table[class_idx, fi, :, j + 1, :]


@dataclass
class Forecast:
    """The grinding forecast of a state (units as in rail_msgs/CorrugationState)."""

    growth_per_axle_pass: np.ndarray   # per band: its fastest component's [1/axle pass]
    worst_band: int
    passes_to_threshold: float
    days_to_threshold: float
    passes_per_day: float
    grinding_due: bool
    grinding_due_ns: int            # 0: never


@dataclass(frozen=True)
class StateSnapshot:
    """What a CorrugationState carries besides the forecast (units as in the message)."""

    newest_ns: int
    newest_train_id: str
    pass_count: int
    axle_pass_count: int
    total_pass_count: int
    last_grinding_ns: int
    bands: np.ndarray
    amplitude: np.ndarray
    threshold: np.ndarray
    grinding_amplitude: np.ndarray
    k_b: np.ndarray


@dataclass
class Trajectory:
    """The state after each counted pass of a history (batch mode): arrays over counted passes.

    index: row of each counted pass in the history given; constants: the snapshot before the
    history (bands, thresholds, post-grinding amplitudes, K_b, last grinding).
    """

    index: np.ndarray
    stamp_ns: np.ndarray
    train_id: np.ndarray
    amplitude: np.ndarray          # (M, B) [m]
    pass_count: np.ndarray
    axle_pass_count: np.ndarray
    total_pass_count: np.ndarray
    forecast: Forecast             # of arrays (M,) and (M, B)
    constants: StateSnapshot

    def __len__(self) -> int:
        return len(self.index)

    def state(self, k: int) -> tuple[StateSnapshot, Forecast]:
        """The snapshot and forecast after counted pass k (for message conversion)."""
        c, f = self.constants, self.forecast
        snap = StateSnapshot(int(self.stamp_ns[k]), str(self.train_id[k]), int(self.pass_count[k]),
                             int(self.axle_pass_count[k]), int(self.total_pass_count[k]), c.last_grinding_ns,
                             c.bands, self.amplitude[k], c.threshold, c.grinding_amplitude, c.k_b)
        return snap, Forecast(f.growth_per_axle_pass[k], int(f.worst_band[k]), float(f.passes_to_threshold[k]),
                              float(f.days_to_threshold[k]), float(f.passes_per_day[k]), bool(f.grinding_due[k]),
                              int(f.grinding_due_ns[k]))

    @classmethod
    def from_rows(cls, rows: list[tuple[int, StateSnapshot, Forecast]], last: StateSnapshot) -> Trajectory:
        """From (history row, snapshot, forecast) per counted pass, taken one by one."""
        def col(get, dtype=float) -> np.ndarray:
            return np.array([get(s, f) for _, s, f in rows], dtype=dtype)

        nb = len(last.bands)
        fc = Forecast(col(lambda s, f: f.growth_per_axle_pass).reshape(-1, nb), col(lambda s, f: f.worst_band, int),
                      col(lambda s, f: f.passes_to_threshold), col(lambda s, f: f.days_to_threshold),
                      col(lambda s, f: f.passes_per_day), col(lambda s, f: f.grinding_due, bool),
                      col(lambda s, f: f.grinding_due_ns, np.int64))
        return cls(np.array([i for i, _, _ in rows], np.int64), col(lambda s, f: s.newest_ns, np.int64),
                   col(lambda s, f: s.newest_train_id, object), col(lambda s, f: s.amplitude).reshape(-1, nb),
                   col(lambda s, f: s.pass_count, np.int64), col(lambda s, f: s.axle_pass_count, np.int64),
                   col(lambda s, f: s.total_pass_count, np.int64), fc, last)


@dataclass
class Evaluation:
    """A speed distribution's growth against the state (units as in EvaluateSpeedDistribution)."""

    growth_per_axle_pass: np.ndarray
    peak_growth: float
    peak_wavelength_m: float
    grinding_interval_factor: float
    days_to_threshold: float


@dataclass
class Advice:
    """Speed advice (units as in rail_msgs/SpeedAdvisory)."""

    mean_speed_mps: float
    min_speed_mps: float
    max_speed_mps: float
    speed_bin_centres_mps: np.ndarray
    current_probability: np.ndarray
    recommended_probability: np.ndarray
    current_peak_growth: float
    recommended_peak_growth: float
    peak_growth_reduction: float
    grinding_interval_factor: float
    current_peak_wavelength_m: float


_RECENT = ("stamp_ns", "train_id", "class_idx", "friction", "speed", "axles")


@dataclass
class _Recent:
    """The kept passes: identity, and what the forecast needs."""

    stamp_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    train_id: np.ndarray = field(default_factory=lambda: np.zeros(0, object))
    class_idx: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    friction: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    speed: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float64))
    axles: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    def extend(self, **cols: np.ndarray) -> None:
        for name in _RECENT:
            setattr(self, name, np.concatenate([getattr(self, name), cols[name]]))

    def keep(self, mask: np.ndarray) -> None:
        for name in _RECENT:
            setattr(self, name, getattr(self, name)[mask])


class CorrugationEstimator:
    """The corrugation state of one site and everything computed from it (no ROS)."""

    def __init__(self, site: Site, cfg: CorrugationConfig, tables: GrowthTables | None = None) -> None:
        self.site, self.cfg = site, cfg
        self.tables = tables or GrowthTables(site, cfg)
        self.tables.set_k_b(cfg.k_b)
        self.bands = self.tables.bands
        acceptance = cg.band_limits(self.bands) * cfg["acceptance_factor"]
        if np.any(np.isnan(acceptance)):
            raise ConfigError("corrugation bands reach outside the 10-3000 mm of the Grassie et al. (1999) limits")
        self.threshold = acceptance * cfg["intervention_factor"]
        self.post_grinding = acceptance * cfg["post_grinding_fraction"]
        self.history_ns = int(cfg["history_days"] * NS_PER_DAY)
        self.points = cfg["points_per_band"]
        self.log_components = self._flat(self.post_grinding)
        self.grinding_amplitude = self.post_grinding.copy()             # r.m.s. after the last grinding
        self.pass_count = self.axle_pass_count = self.total_pass_count = 0
        self.last_grinding_ns = self.newest_ns = 0
        self.newest_train_id = ""                                      # train_id of the newest pass counted
        self.last_survey_ns = 0                                        # last survey or grinding applied
        self.survey_log_amplitude = np.full(len(self.bands), np.nan)   # last survey, NaN: band not measured
        self.recent = _Recent()
        self._seen: set[tuple[int, str]] = set()
        # Running sums over the kept passes of axles x per-axle growth, and of axles (forecast).
        self._growth_sum = np.zeros_like(self.log_components)
        self._axle_sum = 0

    # -- passes ---------------------------------------------------------------------------------
    def advance(self, passes: PassTable) -> np.ndarray:
        """Count the passes not seen before; return the mask of those counted.

        ``passes`` must be valid for the site with class defaults filled. A pass is not counted
        when its (stamp, train_id) was counted already or is older than the kept history.
        """
        return self._advance(passes)[0]

    def _advance(self, passes: PassTable) -> tuple[np.ndarray, np.ndarray]:
        """advance(), also returning ln Z after each counted pass (counted, B, P)."""
        n = len(passes)
        counted = np.zeros(n, bool)
        horizon = self.newest_ns - self.history_ns
        for i, (stamp, tid) in enumerate(zip(passes.stamp_ns.tolist(), passes.train_id, strict=True)):
            key = (stamp, tid)
            if key in self._seen or stamp < horizon:
                continue
            self._seen.add(key)
            counted[i] = True
            horizon = max(horizon, stamp - self.history_ns)
        if not counted.any():
            return counted, np.zeros((0, *self.log_components.shape))
        new = passes.take(counted)
        cls = self.tables.class_index(new.vehicle_class)
        growth = self.tables.at(cls, new.friction_state, new.speed_mps) * new.axle_count[:, None, None]
        # Sequential sum (cumsum), so a batch adds as the same passes one by one would.
        steps = np.cumsum(np.concatenate([self.log_components[None], growth]), axis=0)[1:]
        self.log_components = steps[-1].copy()
        self._growth_sum += growth.sum(axis=0)
        self._axle_sum += int(new.axle_count.sum())
        m = int(counted.sum())
        self.pass_count += m
        self.total_pass_count += m
        self.axle_pass_count += int(new.axle_count.sum())
        i_new = len(new) - 1 - int(np.argmax(new.stamp_ns[::-1]))  # the last of equal stamps, as one by one
        if int(new.stamp_ns[i_new]) >= self.newest_ns:
            self.newest_ns, self.newest_train_id = int(new.stamp_ns[i_new]), str(new.train_id[i_new])
        self.recent.extend(stamp_ns=new.stamp_ns, train_id=new.train_id, class_idx=cls,
                           friction=new.friction_state, speed=new.speed_mps, axles=new.axle_count)
        self._prune()
        return counted, steps

    def advance_history(self, passes: PassTable) -> Trajectory:
        """advance() over a history, returning the state and forecast after every counted pass,
        equal to what the live estimator publishes pass by pass (MODELS.md section 2).

        Vectorised when the passes are in time order and none is older than the newest counted:
        the forecast of pass k then uses the passes within history_days before it, through prefix
        sums. Otherwise the passes are taken one by one.
        """
        stamps = np.asarray(passes.stamp_ns, np.int64)
        r = self.recent
        if len(stamps) and (np.any(np.diff(stamps) < 0) or stamps[0] < self.newest_ns):
            return self._history_one_by_one(passes)
        kept_growth = self.tables.at(r.class_idx, r.friction, r.speed) * r.axles[:, None, None]
        kept_stamps, kept_axles = r.stamp_ns.copy(), r.axles.copy()
        before = self.snapshot()
        counted, steps = self._advance(passes)
        new = passes.take(counted)
        m, k0 = len(new), len(kept_stamps)
        all_stamps = np.concatenate([kept_stamps, new.stamp_ns])
        all_axles = np.concatenate([kept_axles, new.axle_count])
        cls = self.tables.class_index(new.vehicle_class)
        new_growth = self.tables.at(cls, new.friction_state, new.speed_mps) * new.axle_count[:, None, None]
        g_prefix = np.concatenate([np.zeros((1, *steps.shape[1:])), np.cumsum(
            np.concatenate([kept_growth, new_growth]), axis=0)])
        a_prefix = np.concatenate([[0], np.cumsum(all_axles)])
        end = k0 + np.arange(1, m + 1)                                   # one past pass k
        start = np.searchsorted(all_stamps, new.stamp_ns - self.history_ns, side="left")
        axles = (a_prefix[end] - a_prefix[start]).astype(float)
        growth = (g_prefix[end] - g_prefix[start]) / axles[:, None, None]
        span_days = (new.stamp_ns - all_stamps[start]) / NS_PER_DAY
        with np.errstate(divide="ignore", invalid="ignore"):
            rate = np.where((span_days > 0) & (span_days >= self.cfg["min_traffic_days"]),
                            (end - start - 1) / span_days, np.nan)
        fc = self._forecasts(steps, growth, rate, axles / (end - start), new.stamp_ns)
        ordinal = np.arange(1, m + 1)
        return Trajectory(
            index=np.flatnonzero(counted), stamp_ns=new.stamp_ns.copy(), train_id=new.train_id.copy(),
            amplitude=cg.band_amplitude(steps), pass_count=before.pass_count + ordinal,
            axle_pass_count=before.axle_pass_count + np.cumsum(new.axle_count),
            total_pass_count=before.total_pass_count + ordinal, forecast=fc,
            constants=before)

    def _history_one_by_one(self, passes: PassTable) -> Trajectory:
        rows: list[tuple[int, StateSnapshot, Forecast]] = []
        for i in range(len(passes)):
            if self.advance(passes.take(np.arange(len(passes)) == i))[0]:
                rows.append((i, self.snapshot(), self.forecast()))
        return Trajectory.from_rows(rows, self.snapshot())

    def snapshot(self) -> StateSnapshot:
        """The state as a CorrugationState carries it (without the forecast)."""
        return StateSnapshot(self.newest_ns, self.newest_train_id, self.pass_count, self.axle_pass_count,
                             self.total_pass_count, self.last_grinding_ns, self.bands, self.amplitude,
                             self.threshold, self.grinding_amplitude.copy(), self.k_b.copy())

    def _prune(self) -> None:
        keep = self.recent.stamp_ns >= self.newest_ns - self.history_ns
        if not keep.all():
            r = self.recent
            gone = ~keep
            self._growth_sum -= np.einsum("n,nbp->bp", r.axles[gone], self.tables.at(r.class_idx[gone],
                                                                                     r.friction[gone], r.speed[gone]))
            self._axle_sum -= int(r.axles[gone].sum())
            self._seen.difference_update(zip(r.stamp_ns[gone].tolist(), r.train_id[gone].tolist(), strict=True))
            r.keep(keep)

    def _resum(self) -> None:
        """Recompute the running sums from the kept passes (after K_b changes or a load)."""
        r = self.recent
        self._growth_sum = np.einsum("n,nbp->bp", r.axles, self.tables.at(r.class_idx, r.friction, r.speed)) \
            if len(r.stamp_ns) else np.zeros_like(self.log_components)
        self._axle_sum = int(r.axles.sum())

    # -- forecast -------------------------------------------------------------------------------
    def _flat(self, band_rms: np.ndarray) -> np.ndarray:
        """ln Z of components sharing each band's r.m.s. [m] equally, (B, P)."""
        return np.repeat(np.log(band_rms / np.sqrt(self.points))[:, None], self.points, axis=1)

    def recent_growth(self) -> np.ndarray:
        """g per component (B, P) [1/axle pass]: the kept passes' growth, averaged per axle pass."""
        if self._axle_sum == 0:
            return np.zeros((len(self.bands), self.points))
        return self._growth_sum / self._axle_sum

    def traffic(self) -> tuple[float, float]:
        """Recent traffic: (train passes per day, axles per train); NaN rate with fewer than 2 passes or
        over less than min_traffic_days."""
        r = self.recent
        if len(r.stamp_ns) == 0:
            return float("nan"), float("nan")
        span = (int(r.stamp_ns.max()) - int(r.stamp_ns.min())) / NS_PER_DAY
        rate = (len(r.stamp_ns) - 1) / span if span > 0 and span >= self.cfg["min_traffic_days"] else float("nan")
        return rate, float(r.axles.mean())

    def forecast(self, growth: np.ndarray | None = None, passes_per_day: float | None = None) -> Forecast:
        """Time to the intervention threshold per band at growth g and the traffic: for one
        component ln(Z_threshold / Z) / (g x passes per day) (MODELS.md section 2); for a band,
        the energy sum of its components (models.corrugation.passes_to_band_level).

        growth: g per component (B, P) [1/axle pass] (default: the recent passes');
        passes_per_day: train passes [1/day] (default: the recent rate).
        """
        g = self.recent_growth() if growth is None else np.asarray(growth, float)
        rate, axles = self.traffic()
        if passes_per_day:
            rate = passes_per_day
        fc = self._forecasts(self.log_components[None], g[None], np.array([rate]), np.array([axles]),
                             np.array([self.newest_ns]))
        return Forecast(fc.growth_per_axle_pass[0], int(fc.worst_band[0]), float(fc.passes_to_threshold[0]),
                        float(fc.days_to_threshold[0]), float(fc.passes_per_day[0]), bool(fc.grinding_due[0]),
                        int(fc.grinding_due_ns[0]))

    def _forecasts(self, log_components: np.ndarray, growth: np.ndarray, rate: np.ndarray, axles: np.ndarray,
                   newest_ns: np.ndarray) -> Forecast:
        """forecast() for N states at once: ln Z and g (N, B, P), train passes per day and axles
        per train (N,), newest pass time (N,) [ns]; a Forecast of arrays."""
        fallback = float(np.mean([v.mean_axles_per_train for v in self.site.vehicles.values()]))
        axles = np.where(np.isfinite(axles), axles, fallback)
        log_threshold = np.log(self.threshold)
        margin = log_threshold - np.log(cg.band_amplitude(log_components))
        axle_passes = cg.passes_to_band_level(log_components, growth, log_threshold)
        rows = np.arange(len(rate))
        worst = np.where(np.isfinite(axle_passes).any(axis=1), np.argmin(axle_passes, axis=1),
                         np.argmin(margin, axis=1))
        passes = axle_passes[rows, worst] / axles
        with np.errstate(divide="ignore", invalid="ignore"):
            days = np.where(np.isfinite(rate) & (rate > 0), passes / rate, np.inf)
        days = np.where(passes == 0.0, 0.0, days)
        due = (margin.min(axis=1) <= 0) | (days <= self.cfg["lead_time_days"])
        due_ns = np.array([int(t) + int(d * NS_PER_DAY) if np.isfinite(d) else 0
                           for t, d in zip(newest_ns.tolist(), days.tolist(), strict=True)], np.int64)
        return Forecast(growth.max(axis=2), worst, passes, days, rate, due, due_ns)

    # -- surveys and grinding -------------------------------------------------------------------
    def _match(self, wavelength: np.ndarray, amplitude: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Survey values on the state's bands (nominal band centres within 3 %); NaN where absent."""
        wavelength, amplitude = np.asarray(wavelength, float), np.asarray(amplitude, float)
        if wavelength.shape != amplitude.shape or wavelength.ndim != 1:
            raise ValueError("wavelength_m and amplitude_m must be 1-D and the same length")
        if not (np.all(np.isfinite(amplitude)) and np.all(amplitude > 0) and np.all(wavelength > 0)):
            raise ValueError("survey wavelengths and amplitudes must be finite and positive")
        out = np.full(len(self.bands), np.nan)
        for lam, z in zip(wavelength, amplitude, strict=True):
            i = int(np.argmin(np.abs(np.log(self.bands / lam))))
            if abs(np.log(self.bands[i] / lam)) < 0.03:
                out[i] = z
        matched = np.isfinite(out)
        if not matched.any():
            raise ValueError("no survey wavelength matches a band of the state")
        return out, matched

    def apply_survey(self, wavelength: np.ndarray, amplitude: np.ndarray, stamp_ns: int = 0) -> float | None:
        """Take a measured roughness survey: re-fit K_b against the previous survey, then set the
        measured bands to the measurement. Returns the K_b scale applied, or None without a fit.

        g_hat = ln(Z2 / Z1) / (n2 - n1) per band (MODELS.md section 2); since ln|1 + K_b x| is
        K_b x to first order, the scale s minimising sum (ln(Z2/Z1) - s Delta_model)^2 over the
        bands measured twice (Delta_model: the state's ln Z growth since the first survey) scales
        K_b of every friction state (one survey pair cannot separate them). A measured band keeps
        its components' shape, scaled to the measured r.m.s.
        """
        z, matched = self._match(wavelength, amplitude)
        scale = None
        both = matched & np.isfinite(self.survey_log_amplitude)
        dm = self.log_amplitude[both] - self.survey_log_amplitude[both]
        if both.any() and np.dot(dm, dm) > 0:  # no passes since the last survey: nothing to fit
            measured = np.log(z[both]) - self.survey_log_amplitude[both]
            s = float(np.dot(measured, dm) / np.dot(dm, dm))
            if s > 0:
                scale = s
                self.tables.set_k_b(self.tables.k_b * s)
                self._resum()
        self.log_components[matched] += (np.log(z[matched]) - self.log_amplitude[matched])[:, None]
        self.survey_log_amplitude = np.where(matched, np.log(np.where(matched, z, 1.0)), np.nan)
        self.last_survey_ns = max(self.last_survey_ns, int(stamp_ns))
        return scale

    def apply_grinding(self, stamp_ns: int, wavelength: np.ndarray | None = None,
                       amplitude: np.ndarray | None = None) -> None:
        """Reset after grinding: the measured spectrum where given, else the post-grinding default."""
        rms = self.post_grinding.copy()
        self.survey_log_amplitude = np.full(len(self.bands), np.nan)
        if wavelength is not None and len(wavelength):
            z, matched = self._match(wavelength, amplitude)
            rms[matched] = z[matched]
            self.survey_log_amplitude[matched] = np.log(z[matched])
        self.log_components = self._flat(rms)
        self.grinding_amplitude = rms
        self.pass_count = self.axle_pass_count = 0
        self.last_grinding_ns = int(stamp_ns)
        self.last_survey_ns = max(self.last_survey_ns, int(stamp_ns))

    @property
    def amplitude(self) -> np.ndarray:
        """r.m.s. roughness per band [m]."""
        return cg.band_amplitude(self.log_components)

    @property
    def log_amplitude(self) -> np.ndarray:
        return np.log(self.amplitude)

    @property
    def k_b(self) -> np.ndarray:
        return self.tables.k_b

    # -- speed distributions --------------------------------------------------------------------
    def _mix(self, friction_state: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(class index, friction state, axle weight) of the traffic mix: the recent passes', or
        the site's class shares with dry rail when there are none; friction_state > 0 fixes it."""
        r = self.recent
        if len(r.stamp_ns):
            pairs = np.stack([r.class_idx, r.friction])
            keys, inverse = np.unique(pairs, axis=1, return_inverse=True)
            weight = np.bincount(inverse.ravel(), weights=r.axles)
            cls, fr = keys
        else:
            vs = [self.site.vehicle(c) for c in self.tables.classes]
            cls = np.arange(len(vs))
            fr = np.ones(len(vs), np.int64)
            weight = np.array([v.traffic_share * v.mean_axles_per_train for v in vs])
        if friction_state:
            fr = np.full_like(fr, friction_state)
        return cls, fr, weight / weight.sum()

    def growth_at_speeds(self, speeds: np.ndarray, friction_state: int = 0) -> np.ndarray:
        """g per component (B, P, S) [1/axle pass] at each speed [m/s] for the traffic mix."""
        cls, fr, w = self._mix(friction_state)
        s = np.asarray(speeds, float)
        per = self.tables.at(np.repeat(cls, len(s)), np.repeat(fr, len(s)), np.tile(s, len(cls)))
        return np.einsum("m,msbp->bps", w, per.reshape(len(cls), len(s), *per.shape[1:]))

    def evaluate(self, speeds: np.ndarray, probability: np.ndarray, friction_state: int = 0,
                 passes_per_day: float = 0.0) -> Evaluation:
        """Growth per band of a what-if speed distribution, and what it does to the forecast."""
        v, p = np.asarray(speeds, float), np.asarray(probability, float)
        if v.shape != p.shape or v.ndim != 1 or len(v) == 0:
            raise ValueError("speed_mps and probability must be 1-D, non-empty and the same length")
        if not (np.all(np.isfinite(v)) and np.all((v > 0) & (v <= MAX_SPEED_MPS))):
            raise ValueError(f"speeds must be in (0, {MAX_SPEED_MPS:g}] m/s")
        if not (np.all(np.isfinite(p)) and np.all(p >= 0) and p.sum() > 0):
            raise ValueError("probabilities must be finite, non-negative and not all zero")
        if friction_state not in (0, *FRICTION_NAMES):
            raise ValueError(f"friction_state {friction_state} unknown")
        g = self.growth_at_speeds(v, friction_state) @ (p / p.sum())
        current = self.recent_growth().max() if len(self.recent.stamp_ns) else np.nan
        band_g = g.max(axis=1)
        peak = float(band_g.max())
        fc = self.forecast(g, passes_per_day or None)
        return Evaluation(band_g, peak, float(self.bands[int(np.argmax(band_g))]),
                          float(current / peak) if peak > 0 else float("inf"), fc.days_to_threshold)

    def advise(self, speeds: np.ndarray | None = None, weights: np.ndarray | None = None,
               friction_state: int = 0) -> Advice:
        """The distribution with the current mean speed, within the advice limits, with the least peak g.

        Current distribution: the recent passes (axle-weighted), or the given speeds [m/s] with
        weights; the traffic mix is the recent one unless friction_state fixes it.
        """
        r = self.recent
        recent = speeds is None
        if recent:
            if len(r.stamp_ns) == 0:
                raise ValueError("no recent passes to advise on")
            speeds, weights = r.speed, r.axles.astype(float)
        v = np.asarray(speeds, float)
        w = np.ones_like(v) if weights is None else np.asarray(weights, float)
        classes = self.site.vehicles.values()
        lo = self.cfg["advice_min_speed_mps"] or min(c.speed_min_mps for c in classes)
        hi = self.cfg["advice_max_speed_mps"] or max(c.speed_max_mps for c in classes)
        width = self.cfg["advice_bin_mps"]
        edges = np.arange(lo, hi + 0.5 * width, width)
        centres = 0.5 * (edges[:-1] + edges[1:])
        current_p = np.histogram(np.clip(v, lo, hi), edges, weights=w)[0]
        current_p /= current_p.sum()
        mean = float(np.clip(np.average(v, weights=w), centres[0], centres[-1]))
        grid = self.growth_at_speeds(centres, friction_state)
        best = cg.optimise_speed_distribution(grid.reshape(-1, len(centres)), centres, mean,
                                              self.cfg["advice_max_share"])
        # Each recent pass with its own class and friction; a given distribution with the mix.
        g_now = (self.recent_growth() if recent and not friction_state
                 else self.growth_at_speeds(v, friction_state) @ (w / w.sum())).max(axis=1)
        cur_peak = float(g_now.max())
        rec = min(best.peak_growth, cur_peak)
        return Advice(mean, float(lo), float(hi), centres, current_p, best.probability, cur_peak, rec,
                      1.0 - rec / cur_peak if cur_peak > 0 else 0.0,
                      cur_peak / rec if rec > 0 else float("inf"), float(self.bands[int(np.argmax(g_now))]))

    # -- checkpoints ----------------------------------------------------------------------------
    def save(self, path: str | Path) -> None:
        """Write the state atomically: a temporary file, fsync, rename over path, fsync the folder.

        The file it replaces is kept as previous_checkpoint(path). A crash between the two renames
        leaves only that one, which resume() then takes.
        """
        path = Path(path)
        meta = {"version": CHECKPOINT_VERSION, "site_id": self.site.site_id, "pass_count": self.pass_count,
                "axle_pass_count": self.axle_pass_count, "total_pass_count": self.total_pass_count,
                "last_grinding_ns": self.last_grinding_ns, "newest_ns": self.newest_ns,
                "newest_train_id": self.newest_train_id,
                "last_survey_ns": self.last_survey_ns}
        buf = io.BytesIO()
        np.savez(buf, meta=np.array(json.dumps(meta)), bands=self.bands, log_components=self.log_components,
                 k_b=self.k_b, survey_log_amplitude=self.survey_log_amplitude,
                 grinding_amplitude=self.grinding_amplitude,
                 **{f"recent_{n}": self.recent.train_id.astype(str) if n == "train_id" else getattr(self.recent, n)
                    for n in _RECENT})
        tmp = path.with_name(f".{path.name}.tmp")
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, "wb") as fh:
            fh.write(buf.getvalue())
            fh.flush()
            os.fsync(fh.fileno())
        if path.exists():  # keep the last good one: a later fault on the new file falls back to it
            os.replace(path, previous_checkpoint(path))
        os.replace(tmp, path)
        dir_fd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(dir_fd)
        finally:
            os.close(dir_fd)

    def load(self, path: str | Path) -> None:
        """Resume from a checkpoint of this site with the same bands (ConfigError otherwise)."""
        try:
            with np.load(path, allow_pickle=False) as z:
                data = {k: z[k] for k in z.files}  # zip member CRCs are checked as each is read
            meta = json.loads(str(data["meta"]))
            missing = {"bands", "log_components", "k_b", "survey_log_amplitude",
                       *(f"recent_{n}" for n in _RECENT)} - set(data)
            if missing:
                raise KeyError(f"arrays missing: {', '.join(sorted(missing))}")
        except FileNotFoundError:
            raise ConfigError(f"{path}: no such checkpoint") from None
        except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
            raise CorruptCheckpoint(f"{path}: not a readable corrugation checkpoint: "
                                    f"{(str(exc).splitlines() or [type(exc).__name__])[0]}") from None
        if meta.get("version") not in READABLE_VERSIONS or meta.get("site_id") != self.site.site_id:
            raise ConfigError(f"{path}: checkpoint of site {meta.get('site_id')!r} version {meta.get('version')}, "
                              f"not of site {self.site.site_id!r} version {CHECKPOINT_VERSION}")
        if data["bands"].shape != self.bands.shape or not np.allclose(data["bands"], self.bands) \
                or data["log_components"].shape != self.log_components.shape:
            raise ConfigError(f"{path}: checkpoint bands differ from the configured ones")
        self.log_components = data["log_components"].astype(float)
        self.tables.set_k_b(data["k_b"])
        self.survey_log_amplitude = data["survey_log_amplitude"].astype(float)
        self.grinding_amplitude = data.get("grinding_amplitude", self.post_grinding).astype(float)
        for key in ("pass_count", "axle_pass_count", "total_pass_count", "last_grinding_ns", "newest_ns",
                    "last_survey_ns"):
            setattr(self, key, int(meta[key]))
        self.newest_train_id = str(meta.get("newest_train_id", ""))
        self.recent = _Recent(**{n: data[f"recent_{n}"] for n in _RECENT})
        self.recent.train_id = self.recent.train_id.astype(object)
        self._seen = set(zip(self.recent.stamp_ns.tolist(), self.recent.train_id.tolist(), strict=True))
        self._resum()

    def resume(self, path: str | Path) -> tuple[Path | None, list[str]]:
        """Load the newest readable checkpoint: path, else previous_checkpoint(path).

        Returns the file loaded (None: neither exists, the state stays as it is) and one line per
        unreadable file passed over. Both unreadable is CorruptCheckpoint: a restart from zero
        would silently lose the history. A readable checkpoint of another site or other bands is
        ConfigError, with no fallback (the configuration is wrong, not the file).
        """
        skipped: list[str] = []
        for candidate in (Path(path), previous_checkpoint(path)):
            if not candidate.exists():
                continue
            try:
                self.load(candidate)
            except CorruptCheckpoint as exc:
                skipped.append(str(exc))
                continue
            return candidate, skipped
        if skipped:
            raise CorruptCheckpoint("; ".join(skipped) + " (and no readable previous checkpoint)")
        return None, skipped
