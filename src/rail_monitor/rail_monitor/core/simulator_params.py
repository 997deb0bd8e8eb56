"""The traffic simulator's parameters (``simulator.*`` in a site file) and their typed config: the
one place every reader of a site file (rail_monitor.site_file) and the simulator
(rail_monitor.simulation.simulator) take them from."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.errors import ConfigError, RailMonitorError
from rail_monitor.core.params import ParamSpec, resolve
from rail_monitor.core.timeutil import parse_iso_ns

_HOURS_PER_DAY = 24

# A suburban line: morning and evening peaks, about 100 trains a day.
_SUBURBAN_PROFILE = [0.0, 0.0, 0.0, 0.0, 1.0, 3.0, 6.0, 8.0, 8.0, 5.0, 4.0, 4.0,
                     4.0, 4.0, 4.0, 5.0, 7.0, 8.0, 8.0, 6.0, 4.0, 3.0, 2.0, 1.0]

SIMULATOR_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("simulator.seed", 1, "Seed of the random generator (PCG64) [-].", 0, 2**63 - 1),
    ParamSpec("simulator.start_time", "2026-09-01T00:00:00Z", "Start of the simulated history (ISO 8601, UTC)."),
    ParamSpec("simulator.days", 90.0, "Length of the simulated history [day].", 0.0, 36600.0),
    ParamSpec("simulator.trains_per_hour", _SUBURBAN_PROFILE,
              "Mean trains per hour for each hour of the day, 00-01 first [1/h].", 0.0, 1000.0),
    ParamSpec("simulator.curving_factor", 1.2,
              "Leading-axle angle of attack over semi-wheelbase/radius [-].", 0.0, 5.0),
    ParamSpec("simulator.aoa_scatter", 0.35, "Log-normal sigma of the angle of attack [-].", 0.0, 2.0),
    ParamSpec("simulator.wheel_load_sd_fraction", 0.05,
              "Relative standard deviation of wheel load about the class's nominal load [-].", 0.0, 0.5),
    ParamSpec("simulator.wet_fraction", 0.15, "Long-run fraction of hours with a wet rail [-].", 0.0, 0.99),
    ParamSpec("simulator.wet_spell_mean_h", 5.0, "Mean length of a wet spell [h].", 1.0, 1000.0),
    ParamSpec("simulator.leaf_season_start_doy", 274, "First day of year of leaf fall (274 = 1 Oct) [day].", 1, 366),
    ParamSpec("simulator.leaf_season_end_doy", 334, "Last day of year of leaf fall (334 = 30 Nov) [day].", 1, 366),
    ParamSpec("simulator.contaminated_probability", 0.25,
              "Chance a pass in the leaf-fall season meets a contaminated rail [-].", 0.0, 1.0),
    ParamSpec("simulator.friction_modifier_start_day", 45.0,
              "Day (from start) the top-of-rail friction modifier goes into service; negative: never [day].",
              -1.0, 36600.0),
    ParamSpec("simulator.friction_modifier_end_day", 1.0e4,
              "Day (from start) it goes out of service [day].", 0.0, 1.0e6),
    ParamSpec("simulator.friction_modifier_coverage", 0.85,
              "Chance a dry pass sees an effective friction-modifier film while in service [-].", 0.0, 1.0),
)


@dataclass(frozen=True)
class SimulatorConfig:
    """Traffic-generation settings (units as in SIMULATOR_SPECS)."""

    seed: int
    start_ns: int
    days: float
    trains_per_hour: np.ndarray
    curving_factor: float
    aoa_scatter: float
    wheel_load_sd_fraction: float
    wet_fraction: float
    wet_spell_mean_h: float
    leaf_season_start_doy: int
    leaf_season_end_doy: int
    contaminated_probability: float
    friction_modifier_start_day: float
    friction_modifier_end_day: float
    friction_modifier_coverage: float


def simulator_config(values: Mapping[str, Any]) -> SimulatorConfig:
    """Build the config from flat dotted parameter values."""
    v = resolve(SIMULATOR_SPECS, values)
    if len(v["simulator.trains_per_hour"]) != _HOURS_PER_DAY:
        raise ConfigError("parameter 'simulator.trains_per_hour' must have 24 values, one per hour")
    kw = {k.removeprefix("simulator."): val for k, val in v.items()}
    try:
        kw["start_ns"] = parse_iso_ns(kw.pop("start_time"))
    except RailMonitorError as exc:
        raise ConfigError(f"parameter 'simulator.start_time': {exc}") from None
    kw["trains_per_hour"] = np.asarray(kw["trains_per_hour"], dtype=np.float64)
    return SimulatorConfig(**kw)
