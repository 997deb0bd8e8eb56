"""A site parameter file: read without ROS, every name checked against every section's specs.

One YAML file per site, in the ROS 2 parameter-file layout (``/**: ros__parameters: ...``), is
read by every node (``--ros-args --params-file``) and, through :func:`load_parameter_file`, by
the command line and batch mode. This is the one strict path: a name that no section knows (a
typo such as ``vehicle.emu.wheel_diamter_m``) is refused with one line naming it and the nearest
known name, in every section alike.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from rail_monitor.alerts.config import ALERT_SPECS
from rail_monitor.app.simulator import SIMULATOR_SPECS
from rail_monitor.core import node_params
from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, flatten, refuse_unknown
from rail_monitor.core.site import (
    CONTACT_SPECS,
    SITE_SPECS,
    TRACK_SPECS,
    VEHICLE_CLASSES,
    VEHICLE_SPECS,
    Site,
    site_from_values,
)
from rail_monitor.corrugation.config import CORRUGATION_SPECS
from rail_monitor.noise.config import NOISE_SPECS
from rail_monitor.squeal.config import SQUEAL_SPECS

# Every section a site file may hold: (prefix, specs). Vehicle classes are added per name.
SECTIONS: tuple[tuple[str, tuple[ParamSpec, ...]], ...] = (
    ("", SITE_SPECS), ("contact.", CONTACT_SPECS), ("track.", TRACK_SPECS),
    ("corrugation.", CORRUGATION_SPECS), ("squeal.", SQUEAL_SPECS), ("noise.", NOISE_SPECS),
    ("alerts.", ALERT_SPECS), ("stamps.", node_params.STAMP_SPECS), ("", SIMULATOR_SPECS),
    *(("", specs) for specs in (node_params.PUBLISH_SPECS, node_params.REPLAYER_SPECS, node_params.MODE_SPECS,
                                node_params.RECORDER_SPECS, node_params.MONITOR_SPECS, node_params.BATCH_SPECS,
                                node_params.ESTIMATOR_SPECS, node_params.PREDICTOR_SPECS)),
)
# Parameters every rclpy node has, which a parameter file may set too.
ROS_PARAMETERS = ("use_sim_time", "start_type_description_service")


def known_names(values: Mapping[str, Any]) -> set[str]:
    """Every parameter name a site file with these values may hold. Vehicle sections are those of
    its ``vehicle_classes`` (the default's without it); where that is not a list of names (an error
    its own check reports), every ``vehicle.<class>.`` section present is taken as a class."""
    names = {prefix + s.name for prefix, specs in SECTIONS for s in specs} | set(ROS_PARAMETERS)
    classes = values.get(VEHICLE_CLASSES.name, VEHICLE_CLASSES.default)
    if not (isinstance(classes, list) and all(isinstance(c, str) for c in classes)):
        classes = {k.split(".")[1] for k in values if k.startswith("vehicle.") and k.count(".") >= 2}
    return names | {f"vehicle.{c}.{s.name}" for c in classes for s in VEHICLE_SPECS}


def check_names(values: Mapping[str, Any], where: str = "") -> None:
    """ConfigError for the first name no section knows (``qos_overrides.*`` are rclpy's own)."""
    names = [k for k in values if not k.startswith("qos_overrides.")]
    try:
        refuse_unknown(names, known_names(values))
    except ConfigError as exc:
        raise ConfigError(f"{where}{exc}") from None


def load_parameter_file(path: str | Path) -> dict[str, Any]:
    """Read a ROS 2 parameter file into flat dotted names (the ``/**`` section, else the first),
    every name checked (ConfigError naming the file and the parameter)."""
    path = Path(path)
    try:
        doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise ConfigError(f"{path}: cannot read parameter file: {str(exc).splitlines()[0]}") from None
    if not isinstance(doc, Mapping) or not doc:
        raise ConfigError(f"{path}: not a ROS 2 parameter file (expected '/**: ros__parameters: ...')")
    section = doc.get("/**", next(iter(doc.values())))
    if not isinstance(section, Mapping) or not isinstance(section.get("ros__parameters"), Mapping):
        raise ConfigError(f"{path}: no 'ros__parameters' mapping")
    values = flatten(section["ros__parameters"])
    check_names(values, f"{path}: ")
    return values


def load_site(path: str | Path) -> Site:
    """The Site described by a site parameter file."""
    return site_from_values(load_parameter_file(path))
