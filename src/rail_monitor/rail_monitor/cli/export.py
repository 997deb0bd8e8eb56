"""rail-monitor export: a recorded run as tables (one row per pass, one per alert event)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rail_monitor.bagio.output_folder import beside
from rail_monitor.cli.common import add_site_option, bag_site_values, fresh_output


def add_parser(sub: argparse._SubParsersAction) -> None:
    from rail_monitor.report.export import FORMATS

    s = sub.add_parser("export", help="write a recorded run as tables: passes (every model output per pass) and "
                       "alerts, as CSV, Parquet or an Excel workbook")
    s.add_argument("bag", help="bag recorded by the graph or by batch")
    s.add_argument("--format", choices=FORMATS, default="csv", help="file format (default: csv)")
    s.add_argument("--output", help="folder to write into (default: <bag>_export next to the bag)")
    s.add_argument("--chunk", type=int, default=5_000, help="passes read and written at a time for CSV and "
                   "Parquet (default 5000; 0: read the bag whole)")
    add_site_option(s, default="the site stored in the bag")
    s.add_argument("--overwrite", action="store_true", help="replace an existing export folder that rail_monitor "
                   "created")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:

    from rail_monitor import __version__
    from rail_monitor.bagio.output_folder import claim_output_folder
    from rail_monitor.bagio.site_record import read_site_record
    from rail_monitor.core.text import printable
    from rail_monitor.engine.site_config import SiteConfig
    from rail_monitor.report.export import export_run

    values, _ = bag_site_values(ns.bag, ns.site)
    record = read_site_record(ns.bag) or {}
    about = {"rail_monitor.version": __version__, "source bag": str(Path(ns.bag).absolute()),
             "site_id": str(values.get("site_id", "")), **{f"site.{k}": v for k, v in record.items()}}
    out = Path(ns.output) if ns.output else beside(ns.bag, "_export")
    fresh_output(out, ns.overwrite, [ns.bag])
    claim = claim_output_folder(out)
    try:
        done = export_run(ns.bag, SiteConfig.from_values(values), ns.format, claim.folder, about, ns.chunk)
    except BaseException:
        claim.release()  # claimed above: a failed export leaves nothing behind, and nothing else goes
        raise
    for line in done.notes:
        print(f"export: {printable(line)}")
    for name, rows, cols in done.tables:
        print(f"export: {name}: {rows} rows, {cols} columns")
    print("export: " + ", ".join(printable(f) for f in done.files))
    return 0
