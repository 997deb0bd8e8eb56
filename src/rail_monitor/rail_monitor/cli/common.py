"""What every verb of the command line shares: the site option, node parameters as options,
ROS arguments, output folders, the run summary and report, JSON output."""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rail_monitor.core.errors import ConfigError, RailMonitorError
from rail_monitor.core.params import ParamSpec
from rail_monitor.core.text import jsonable

SALVAGE_HELP = ("read every complete chunk of an MCAP file cut off mid-write (a killed recorder, a full disk) "
                "and say how many messages it recovered")


def site_file(path: str | None) -> Path:
    """The site parameter file given, or the shipped curve_250.yaml."""
    from rail_monitor.site_file import shipped_site_file

    return Path(path) if path else shipped_site_file()


def site_values(path: str | None) -> dict[str, Any]:
    """The flat parameter values of the site file given (or the shipped one), every name checked."""
    from rail_monitor.site_file import load_parameter_file

    return load_parameter_file(site_file(path))


def add_site_option(parser: argparse.ArgumentParser, what: str = "site parameter file",
                    default: str = "the shipped curve_250.yaml") -> None:
    parser.add_argument("--site", help=f"{what} (default: {default})")


def stored_site(path: str | None) -> dict[str, str]:
    """The record of the site file given (or the shipped one) to store with a bag."""
    from rail_monitor.bagio.site_record import site_record

    return site_record(site_file(path))


def bag_site_values(bag: str | Path, site: str | None) -> tuple[dict[str, Any], str]:
    """The site values to read a bag with, and a line naming them: --site if given (a warning on
    stderr if it differs from the site stored in the bag), else the bag's own site, else the
    shipped one (with a note)."""
    from rail_monitor.bagio.site_record import describe, read_site_record
    from rail_monitor.core.errors import InputError
    from rail_monitor.site_file import load_parameter_file

    if not Path(bag).exists():
        raise InputError(f"{bag}: no such file or folder")
    record = read_site_record(bag)
    stored = load_parameter_file(f"{bag}:{record['site_file_name']}", record["site_file"]) if record else None
    if site:
        values = site_values(site)
        if stored is not None and stored != values:
            differ = sorted(k for k in set(values) | set(stored) if values.get(k) != stored.get(k))
            print(f"warning: --site {site} differs from the site stored in {bag}, {describe(record)}, in "
                  f"{len(differ)} parameter(s) ({', '.join(differ[:4])}{', ...' if len(differ) > 4 else ''}); "
                  "using --site", file=sys.stderr)
        return values, f"{site} (given with --site)"
    if stored is not None:
        print(f"site: {describe(record)}, stored in the bag")
        return stored, f"{describe(record)}, stored in the bag"
    print(f"site: {bag} stores no site file; using the shipped curve_250.yaml (give --site)", file=sys.stderr)
    return site_values(None), f"{site_file(None)} (the shipped default: the bag stores no site file)"


def add_specs(parser: argparse.ArgumentParser, specs: Sequence[ParamSpec], skip: Sequence[str] = ()) -> None:
    """An option per node parameter (name, unit, range and default from its spec)."""
    group = parser.add_argument_group("node parameters (ROS 2 parameter in brackets)")
    for s in specs:
        if s.name in skip:
            continue
        flag = "--" + s.name.replace("_", "-").replace(".", "-")
        extra = f" {s.range_text()}" if (s.low is not None or s.high is not None or s.choices) else ""
        kw: dict = {"dest": "p:" + s.name, "default": None, "metavar": s.kind.__name__.upper(),
                    "help": f"{s.description}{extra} default: {s.default!r} [{s.name}]"}
        if isinstance(s.default, list):
            kw["nargs"] = "*"
        if s.kind is bool:
            kw.update(action=argparse.BooleanOptionalAction, metavar=None)
        else:
            kw["type"] = s.kind
        group.add_argument(flag, **kw)


def _ros_value(v: object) -> str:
    """A parameter value in ROS 2 command-line YAML."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, list):
        return "[" + ",".join(f"'{x}'" if isinstance(x, str) else repr(x) for x in v) + "]"
    if isinstance(v, str):
        return f"'{v}'" if v else "''"
    return repr(v)


def ros_args(ns: argparse.Namespace, site: Path | None, extra: dict[str, object]) -> list[str]:
    """argv for rclpy.init: the site file, the namespace, every option given, then the user's own
    ROS arguments.

    rcl takes a node's own section of a params file (``/**/corrugation_estimator``) over any
    ``-p``, so a ``-p`` could never override what the site file sets for one node. With a site
    file, the options and the user's ``-p name:=value`` go into an overrides file placed after it,
    under ``/**`` and under every section of the site file that sets the name: a later file wins
    at the same specificity, so what the user asked for is what the node gets."""
    values = {k[2:]: v for k, v in vars(ns).items() if k.startswith("p:") and v is not None}
    values.update({k: v for k, v in extra.items() if v is not None})
    user = list(getattr(ns, "ros_extra", []))
    args = ["rail-monitor", "--ros-args"]
    if getattr(ns, "namespace", None):
        args += ["-r", f"__ns:=/{ns.namespace.strip('/')}"]
    if site is None:
        return args + [a for name, v in values.items() for a in ("-p", f"{name}:={_ros_value(v)}")] + user
    rest, given = _split_parameter_rules(user)
    values.update(given)
    return [*args, "--params-file", str(site), "--params-file", str(_overrides_file(site, values)), *rest]


def _split_parameter_rules(argv: list[str]) -> tuple[list[str], dict[str, object]]:
    """The ROS arguments without their -p/--param rules, and those rules' values (parsed as YAML,
    as rcl parses them)."""
    from rail_monitor.core.yaml_text import load_yaml

    rest, values, i = [], {}, 0
    while i < len(argv):
        if argv[i] in ("-p", "--param") and i + 1 < len(argv) and ":=" in argv[i + 1]:
            name, text = argv[i + 1].split(":=", 1)
            values[name] = load_yaml(text, f"-p {name}", ConfigError) if text else ""
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    return rest, values


def _overrides_file(site: Path, values: dict[str, object]) -> Path:
    """A params file of values under ``/**`` and under each section of the site file setting them
    (removed at exit: this process made it)."""
    import atexit
    import tempfile

    import yaml

    from rail_monitor.site_file import parameter_sections

    out: dict[str, dict] = {"/**": {"ros__parameters": dict(values)}}
    for section, params in parameter_sections(site).items():
        mine = {k: v for k, v in values.items() if k in params}
        if mine and section != "/**":
            out[section] = {"ros__parameters": mine}
    fd, name = tempfile.mkstemp(prefix="rail_monitor_overrides_", suffix=".yaml")
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        yaml.safe_dump(out, f, sort_keys=False)
    atexit.register(lambda: Path(name).unlink(missing_ok=True))
    return Path(name)


def fresh_output(path: Path, overwrite: bool, inputs: Sequence[str | Path] = ()) -> None:
    """Make room for an output folder. Without overwrite an existing path is refused; with it, only
    a folder this program created (it holds the marker file of bagio.mcap_bag) is removed, and never
    the working folder, a folder holding an input, or a symbolic link."""
    from rail_monitor.bagio.output_folder import MARKER

    if not (path.exists() or path.is_symlink()):
        return
    if not overwrite:
        raise RailMonitorError(f"{path} exists; remove it or pass --overwrite")
    if path.is_symlink():
        raise RailMonitorError(f"{path} is a symbolic link: --overwrite replaces only folders rail_monitor created")
    real = path.resolve()
    if real == Path.cwd().resolve() or real in Path.cwd().resolve().parents:
        raise RailMonitorError(f"{path} is the working folder or holds it: give another output folder")
    for source in inputs:
        src = Path(source).resolve()
        if real == src or real in src.parents:
            raise RailMonitorError(f"{path} holds the input {source}: give another output folder")
    if not path.is_dir() or not (path / MARKER).is_file():
        raise RailMonitorError(f"{path} exists and was not created by rail_monitor (no {MARKER} file): "
                               "remove it yourself or give another output folder")
    shutil.rmtree(path)


def report_dir(bag: str, report: str | None) -> Path:
    return Path(report) if report else Path(f"{str(bag).rstrip('/')}_report")


def print_report(bag: str, site: str | None, report: str | None, listen: int = 3,
                 archive: str | None = None) -> None:
    """Print the run summary and write the report folder."""
    from rail_monitor.engine.site_config import SiteConfig
    from rail_monitor.report.run_data import load_run
    from rail_monitor.report.summary import build_report, summary_lines

    values, site_text = bag_site_values(bag, site)
    cfg = SiteConfig.from_values(values)
    run = load_run(bag)
    print("\n".join(summary_lines(run, cfg)))
    files = build_report(run, cfg, report_dir(bag, report), site_text, listen, archive)
    pngs = sum(f.suffix == ".png" for f in files)
    print(f"report: {files[-1]} ({pngs} figures; report.pdf, squealing_trains.csv, summary.json beside it)")


def print_json(data: Any) -> None:
    """Print data as strict JSON (see :func:`jsonable`)."""
    print(json.dumps(jsonable(data), indent=1, allow_nan=False))
