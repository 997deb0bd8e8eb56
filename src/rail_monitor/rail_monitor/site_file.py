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

from rail_monitor.alerts.config import ALERT_SPECS
from rail_monitor.core import node_params
from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, flatten, refuse_unknown
from rail_monitor.core.simulator_params import SIMULATOR_SPECS
from rail_monitor.core.site import (
    CONTACT_SPECS,
    SITE_SPECS,
    TRACK_SPECS,
    VEHICLE_CLASSES,
    VEHICLE_SPECS,
    Site,
    site_from_values,
)
from rail_monitor.core.user_file import read_user_text
from rail_monitor.core.yaml_text import load_yaml
from rail_monitor.corrugation.config import CORRUGATION_SPECS
from rail_monitor.economics.config import ECONOMICS_SPECS
from rail_monitor.measured.config import RESIDUAL_SPECS
from rail_monitor.noise.config import NOISE_SPECS
from rail_monitor.squeal.config import SQUEAL_SPECS
from rail_monitor.station.config import STATION_SPECS

# Every section a site file may hold: (prefix, specs). Vehicle classes are added per name.
SECTIONS: tuple[tuple[str, tuple[ParamSpec, ...]], ...] = (
    ("", SITE_SPECS), ("contact.", CONTACT_SPECS), ("track.", TRACK_SPECS),
    ("corrugation.", CORRUGATION_SPECS), ("squeal.", SQUEAL_SPECS), ("noise.", NOISE_SPECS),
    ("alerts.", ALERT_SPECS), ("residual.", RESIDUAL_SPECS), ("stamps.", node_params.STAMP_SPECS),
    ("station.", STATION_SPECS), ("economics.", ECONOMICS_SPECS),
    ("", SIMULATOR_SPECS),
    *(("", specs) for specs in (node_params.PUBLISH_SPECS, node_params.REPLAYER_SPECS, node_params.MODE_SPECS,
                                node_params.RECORDER_SPECS, node_params.MONITOR_SPECS, node_params.BATCH_SPECS,
                                node_params.ESTIMATOR_SPECS, node_params.PREDICTOR_SPECS,
                                node_params.FOXGLOVE_SPECS, node_params.PLANNER_SPECS)),
)
# Parameters every rclpy node has, which a parameter file may set too.
ROS_PARAMETERS = ("use_sim_time", "start_type_description_service")


def known_specs(values: Mapping[str, Any]) -> dict[str, ParamSpec]:
    """The spec of every parameter a site file with these values may hold, by full name. Vehicle
    sections are those of its ``vehicle_classes`` (the default's without it); where that is not a
    list of names (an error its own check reports), every ``vehicle.<class>.`` section present is
    taken as a class."""
    specs = {prefix + s.name: s for prefix, section in SECTIONS for s in section}
    classes = values.get(VEHICLE_CLASSES.name, VEHICLE_CLASSES.default)
    if not (isinstance(classes, list) and all(isinstance(c, str) for c in classes)):
        classes = {k.split(".")[1] for k in values if k.startswith("vehicle.") and k.count(".") >= 2}
    specs.update({f"vehicle.{c}.{s.name}": s for c in classes for s in VEHICLE_SPECS})
    return specs


def known_names(values: Mapping[str, Any]) -> set[str]:
    """Every parameter name a site file with these values may hold (see :func:`known_specs`)."""
    return set(known_specs(values)) | set(ROS_PARAMETERS)


def check_names(values: Mapping[str, Any], where: str = "") -> None:
    """ConfigError for the first name no section knows (``qos_overrides.*`` are rclpy's own)."""
    names = [k for k in values if not k.startswith("qos_overrides.")]
    try:
        refuse_unknown(names, known_names(values))
    except ConfigError as exc:
        raise ConfigError(f"{where}{exc}") from None


def _read_document(path: Path, text: str | None = None) -> Mapping[str, Any]:
    text = read_user_text(path, "a parameter file", error=ConfigError) if text is None else text
    doc = load_yaml(text, f"{path}: cannot read parameter file", ConfigError)
    if not isinstance(doc, Mapping) or not doc:
        raise ConfigError(f"{path}: not a ROS 2 parameter file (expected '/**: ros__parameters: ...')")
    return doc


def _parameters(path: Path, section: Any) -> dict[str, Any]:
    if not isinstance(section, Mapping) or not isinstance(section.get("ros__parameters"), Mapping):
        raise ConfigError(f"{path}: no 'ros__parameters' mapping")
    return flatten(section["ros__parameters"])


def load_parameter_file(path: str | Path, text: str | None = None) -> dict[str, Any]:
    """Read a ROS 2 parameter file into flat dotted names (the ``/**`` section, else the first),
    every name checked (ConfigError naming the file and the parameter). text: the file's content
    when it comes from elsewhere (a site stored in a bag), path then only names it."""
    path = Path(path)
    doc = _read_document(path, text)
    values = _parameters(path, doc.get("/**", next(iter(doc.values()))))
    check_names(values, f"{path}: ")
    return values


def parameter_sections(path: str | Path) -> dict[str, dict[str, Any]]:
    """Every section of a ROS 2 parameter file (``/**``, ``/**/<node>``, ...) as flat dotted
    names, names not checked (ConfigError naming the file if it is not a parameter file)."""
    path = Path(path)
    return {str(node): _parameters(path, section) for node, section in _read_document(path).items()}


def check_parameter_file(path: str | Path) -> None:
    """ConfigError for the first parameter of any section of a ROS 2 parameter file that its spec
    refuses: an unknown name, a wrong type (a YAML integer for a double, as rcl reads it), a value
    out of range. rcl merges the files given to a node and drops, without a word, a later file's
    value whose type differs from an earlier one's: each file is checked on its own first."""
    path = Path(path)
    for node, values in parameter_sections(path).items():
        where = f"{path}: section '{node}': "
        check_names(values, where)
        specs = known_specs(values)
        for name, value in values.items():
            spec = specs.get(name)
            if spec is None:  # rclpy's own (use_sim_time, qos_overrides.*)
                continue
            items = value if isinstance(value, list) else [value]
            if spec.kind is float and any(isinstance(v, int) and not isinstance(v, bool) for v in items):
                raise ConfigError(f"{where}parameter '{name}' must be a double: write {value!r} with a decimal point")
            try:
                spec.check(value, name[:-len(spec.name)])
            except ConfigError as exc:
                raise ConfigError(f"{where}{exc}") from None


def shipped_site_file() -> Path:
    """The example site file, curve_250.yaml, shipped with the package: the default wherever no site
    is given (also installed to the package's share/config for ros2 launch)."""
    return Path(__file__).parent / "site_files" / "curve_250.yaml"


def load_site(path: str | Path) -> Site:
    """The Site described by a site parameter file."""
    return site_from_values(load_parameter_file(path))


# -- the parameters reference (docs/parameters.md) ------------------------------------------------
REFERENCE_SECTIONS: tuple[tuple[str, str, tuple[ParamSpec, ...]], ...] = (
    ("Site", "", SITE_SPECS), ("Wheel-rail contact", "contact.", CONTACT_SPECS), ("Track", "track.", TRACK_SPECS),
    ("Vehicle class (one section per name in vehicle_classes)", "vehicle.<class>.", VEHICLE_SPECS),
    ("Corrugation", "corrugation.", CORRUGATION_SPECS), ("Squeal", "squeal.", SQUEAL_SPECS),
    ("Rolling noise", "noise.", NOISE_SPECS), ("Alerts", "alerts.", ALERT_SPECS),
    ("Measured noise: residuals", "residual.", RESIDUAL_SPECS),
    ("Noise station (noise_station)", "station.", STATION_SPECS),
    ("Grinding economics (rail-monitor plan)", "economics.", ECONOMICS_SPECS),
    ("Stamp plausibility", "stamps.", node_params.STAMP_SPECS), ("Simulator", "", SIMULATOR_SPECS),
    ("Pass sources (pass_replayer, pass_simulator)", "", node_params.PUBLISH_SPECS),
    ("pass_replayer", "", node_params.REPLAYER_SPECS), ("pass_simulator and pass_replayer: mode", "",
                                                         node_params.MODE_SPECS),
    ("mcap_recorder", "", node_params.RECORDER_SPECS), ("wayside_monitor", "", node_params.MONITOR_SPECS),
    ("Model nodes: batches of passes", "", node_params.BATCH_SPECS),
    ("corrugation_estimator and site_engine", "", node_params.ESTIMATOR_SPECS),
    ("rolling_noise_predictor", "", node_params.PREDICTOR_SPECS), ("foxglove_server", "", node_params.FOXGLOVE_SPECS),
    ("grinding_planner", "", node_params.PLANNER_SPECS),
)


def parameters_markdown() -> str:
    """Every parameter a site file may hold, as Markdown tables generated from the specs (the
    parameters reference; ``python -m rail_monitor.site_file`` prints it)."""
    def cell(text: object) -> str:
        return str(text).replace("|", "\\|").replace("\n", " ")

    command = "ros2_ws/run python -m rail_monitor.site_file > docs/parameters.md"
    lines = ["# Parameters reference", "",
             f"Generated from the parameter specs by `{command}`",
             "(a test checks that this page is current). Every name may appear in a site file; the nodes",
             "declare them as ROS 2 parameters with the same ranges. Units are in brackets at the end of",
             "each description. Tunable: may be changed on a running node (`ros2 param set`).", ""]
    for title, prefix, specs in REFERENCE_SECTIONS:
        lines += [f"## {title}", "", "| parameter | type | default | allowed | tunable | description |",
                  "|---|---|---|---|---|---|"]
        for spec in specs:
            kind = f"{spec.kind.__name__}[]" if isinstance(spec.default, list) else spec.kind.__name__
            allowed = "" if spec.kind in (bool, str) and not spec.choices else spec.range_text()
            lines.append(f"| `{prefix}{spec.name}` | {kind} | `{spec.default!r}` | {cell(allowed)} | "
                         f"{'yes' if spec.tunable else ''} | {cell(spec.description)} |")
        lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    print(parameters_markdown(), end="")
