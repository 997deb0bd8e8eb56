"""rail-monitor site: a new site file from the shipped one (or another), with parameters changed,
comments kept, and the result checked by the one strict path before it is written."""

from __future__ import annotations

import argparse
import io
from pathlib import Path
from typing import Any

from rail_monitor.cli.common import add_site_option, site_file
from rail_monitor.core.errors import ConfigError, RailMonitorError
from rail_monitor.core.user_file import read_user_text
from rail_monitor.core.yaml_text import load_yaml


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("site", help="write a new site file: a copy of the shipped one (or --site) with parameters "
                       "changed (--set NAME=VALUE), checked before it is written")
    s.add_argument("output", help="site file to create (.yaml); an existing file is never replaced")
    add_site_option(s, what="site file to start from")
    s.add_argument("--set", dest="changes", action="append", default=[], metavar="NAME=VALUE",
                   help="a parameter and its value as YAML (e.g. curve_radius_m=400.0, "
                        "vehicle.freight.traffic_share=0.5); repeat for more")
    s.add_argument("--cnossos-catalogue", metavar="CSV", help="a file of your own CNOSSOS-EU tables in the package's "
                   "format (track, vehicle and traction spectra, contact filters), stored in the site file as "
                   "noise.cnossos_catalogue")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.noise.config import check_traction, noise_config
    from rail_monitor.site_file import check_parameter_file, load_parameter_file, load_site

    out = Path(ns.output)
    if out.exists() or out.is_symlink():
        raise RailMonitorError(f"{out} exists: give a new file name (a site file is never replaced)")
    literal = {}
    if ns.cnossos_catalogue:
        literal["noise.cnossos_catalogue"] = read_user_text(ns.cnossos_catalogue, "a CNOSSOS-EU catalogue")
    source = site_file(ns.site)
    original = read_user_text(source, "a parameter file", error=ConfigError)
    load_yaml(original, f"{source}: cannot read parameter file", ConfigError)  # one line for any YAML fault
    text, changed = edited_site_text(original, ns.changes, literal)
    tmp = out.with_name(f".{out.name}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        check_parameter_file(tmp)
        site = load_site(tmp)
        check_traction(site, noise_config(load_parameter_file(tmp)))   # terms that depend on each other
        tmp.replace(out)
    except OSError as exc:
        raise RailMonitorError(f"{out}: cannot write: {exc.strerror or exc}") from None
    except ConfigError as exc:
        raise ConfigError(str(exc).replace(str(tmp), str(out))) from None
    finally:
        tmp.unlink(missing_ok=True)  # this command made it
    for line in changed:
        print(f"site: {line}")
    print(f"site: wrote {out} (site {site.site_id}, {len(site.vehicles)} vehicle classes), checked")
    return 0


def edited_site_text(text: str, changes: list[str], literal: dict[str, str] | None = None) -> tuple[str, list[str]]:
    """The site file's text with each NAME=VALUE set where the file sets NAME (in whichever
    section), else under ``/**``; comments and layout kept (ruamel.yaml round trip). literal: names
    set to a text kept line for line (a YAML block scalar). Returns the text and a line per change."""
    from ruamel.yaml import YAML
    from ruamel.yaml.scalarstring import LiteralScalarString

    rt = YAML()
    rt.preserve_quotes = True
    rt.width = 4096
    doc = rt.load(text)
    lines = []
    for change in changes:
        name, sep, raw = change.partition("=")
        if not sep or not name.strip():
            raise RailMonitorError(f"--set {change!r}: expected NAME=VALUE")
        value = load_yaml(raw, f"--set {change!r}: the value", RailMonitorError)
        old = _set(doc, name.strip(), value)
        lines.append(f"{name.strip()}: {old!r} -> {value!r}")
    for name, block in (literal or {}).items():
        _set(doc, name, LiteralScalarString(block))
        lines.append(f"{name}: {len(block.splitlines())} lines set")
    buf = io.StringIO()
    rt.dump(doc, buf)
    return buf.getvalue(), lines


def _set(doc: Any, name: str, value: Any) -> Any:
    """Set a dotted name where a section of doc has it, else under /**; returns the old value."""
    keys = name.split(".")
    for section in doc.values():
        params = section.get("ros__parameters") if hasattr(section, "get") else None
        node = params
        for k in keys[:-1]:
            node = node.get(k) if hasattr(node, "get") else None
        if hasattr(node, "get") and keys[-1] in node:
            old = node[keys[-1]]
            node[keys[-1]] = value
            return old
    node = doc.setdefault("/**", {}).setdefault("ros__parameters", {})
    for k in keys[:-1]:
        node = node.setdefault(k, {})
    node[keys[-1]] = value
    return None
