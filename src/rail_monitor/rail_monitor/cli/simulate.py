"""rail-monitor simulate: a seeded pass history for a site, into a bag and/or a CSV file."""

from __future__ import annotations

import argparse
from pathlib import Path

from rail_monitor.cli.common import add_site_option, fresh_output, site_values
from rail_monitor.core.errors import RailMonitorError


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("simulate", help="generate a seeded pass history for a site into a bag and/or CSV")
    add_site_option(s)
    s.add_argument("--out", help="bag folder to create (MCAP)")
    s.add_argument("--csv", help="CSV file to write")
    s.add_argument("--days", type=float, help="override simulator.days [day]")
    s.add_argument("--seed", type=int, help="override simulator.seed [-]")
    s.add_argument("--force", action="store_true", help="replace an existing bag folder that rail_monitor created")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.app.simulator import simulate, simulator_config
    from rail_monitor.bagio.csv_io import write_csv
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.core.site import site_from_values

    values = site_values(ns.site)
    if ns.days is not None:
        values["simulator.days"] = ns.days
    if ns.seed is not None:
        values["simulator.seed"] = ns.seed
    site = site_from_values(values)
    table = simulate(site, simulator_config(values))
    if not ns.out and not ns.csv:
        raise RailMonitorError("give --out BAG and/or --csv FILE")
    if ns.out:
        fresh_output(Path(ns.out), ns.force)
        write_passes_bag(table, ns.out, site.site_id)
        print(f"wrote {len(table)} passes to bag {ns.out}")
    if ns.csv:
        write_csv(table, ns.csv)
        print(f"wrote {len(table)} passes to {ns.csv}")
    return 0
