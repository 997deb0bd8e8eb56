"""rail-monitor batch: the graph's models over a whole history without DDS, recorded like the graph."""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from rail_monitor.bagio.output_folder import beside
from rail_monitor.cli.common import (
    SALVAGE_HELP,
    add_site_option,
    fresh_output,
    print_report,
    site_values,
    stored_site,
)
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.text import printable


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("batch", help="the graph's models over a whole history without DDS (vectorised), "
                       "recorded to a bag like the live graph, with the report")
    s.add_argument("source", nargs="?", help="bag folder, .mcap, .db3 or .csv (or give --manifest)")
    add_site_option(s)
    s.add_argument("--topic", help="TrainPass topic of the bag (default: the only one)")
    s.add_argument("--output", help="bag folder to write (default: <source>_batch next to the source)")
    s.add_argument("--namespace", help="topic namespace in the bag (default: the site_id)")
    s.add_argument("--report", help="report folder (default: <output>_report)")
    s.add_argument("--no-report", action="store_true", help="write the bag only")
    s.add_argument("--overwrite", action="store_true",
                   help="replace an existing output folder that rail_monitor created")
    s.add_argument("--salvage", action="store_true", help=SALVAGE_HELP)
    s.add_argument("--measured", help="measured pass-bys: a noise station's CSV (see the user guide) or a bag "
                   "(default: the source bag's own)")
    s.add_argument("--surveys", nargs="+", default=[], metavar="BAG",
                   help="bags of roughness surveys or grinding events to apply with the source's own (e.g. "
                   "rail-monitor measure roughness --survey-bag)")
    s.add_argument("--chunk", type=int, default=5_000,
                   help="passes read, run and recorded at a time from a bag (memory: about 12 kB a pass; the "
                   "outputs do not depend on it) (default: 5000)")
    s.add_argument("--skip-bad-rows", action="store_true",
                   help="CSV: leave malformed rows out (counted, their lines named) instead of failing")
    m = s.add_argument_group("many sites (a Dask cluster)")
    m.add_argument("--manifest", help="YAML list of sites (site:, history:, output:), one task per site; "
                   "outputs per site, no report")
    m.add_argument("--workers", type=int, default=0, help="worker processes of the local cluster (default: one "
                   "per core)")
    m.add_argument("--scheduler", help="address of a running Dask scheduler (e.g. tcp://10.0.0.5:8786) instead "
                   "of a local cluster")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    if bool(ns.manifest) == bool(ns.source):
        raise RailMonitorError("give a source, or --manifest for many sites (not both)")
    if ns.manifest:
        return _many_sites(ns)
    if ns.chunk < 1:
        raise RailMonitorError(f"--chunk must be a positive number of passes, not {ns.chunk}")
    from rail_monitor.batch.bag import record_history

    t0 = time.monotonic()
    values = site_values(ns.site)
    out = Path(ns.output) if ns.output else beside(ns.source, "_batch")
    fresh_output(out, ns.overwrite, [ns.source])
    rec = record_history(ns.source, values, out, ns.namespace if ns.namespace is not None else
                         str(values.get("site_id", "")), stored_site(ns.site), ns.topic, ns.chunk, ns.skip_bad_rows,
                         ns.salvage, ns.measured, ns.surveys)
    for line in rec.notes:
        print(f"batch: {line}")
    for why, count in rec.left_out.items():
        print(f"batch: {count} pass(es) left out: {why}")
    if rec.events:
        print(f"batch: {rec.events} roughness survey(s) and grinding event(s) read: {rec.events_applied} applied "
              f"in stamp order, {rec.events - rec.events_applied} refused")
    for why, count in rec.events_refused.items():
        print(f"batch: {count} survey or grinding event(s) refused: {why}")
    if rec.measurements:
        print(f"batch: {rec.measurements} measured pass-by(s) paired with their predictions, "
              f"{sum(rec.measurements_refused.values())} refused")
    for why, count in rec.measurements_refused.items():
        print(f"batch: {count} measured pass-by(s) refused: {why}")
    t = time.monotonic() - t0
    print(f"batch: {rec.passes} passes through the models and recorded to {out} in {t:.2f} s "
          f"({rec.passes / max(t, 1e-9):.0f} passes/s)" + (f"; {rec.read} read" if rec.read != rec.passes else ""))
    if not ns.no_report:
        print_report(str(out), ns.site, ns.report)
    return 0


def _many_sites(ns: argparse.Namespace) -> int:
    from rail_monitor.batch.sites import read_manifest, run_sites

    jobs = read_manifest(ns.manifest)
    t0 = time.monotonic()
    results = run_sites(jobs, ns.workers, ns.scheduler or "")
    wall = time.monotonic() - t0
    for r in results:
        days = f"grinding in {r.days_to_threshold:.0f} days" if r.days_to_threshold < 1e9 else "no grinding forecast"
        print(f"batch: site {printable(r.site_id)}: {r.passes} passes ({r.rejected} rejected), {r.alert_events} "
              f"alert events, {days}; {r.seconds:.1f} s on {r.worker}; recorded to {printable(r.output)}")
    total = sum(r.passes for r in results)
    print(f"batch: {len(results)} sites, {total} passes in {wall:.1f} s ({total / max(wall, 1e-9):.0f} passes/s, "
          f"{len({r.worker for r in results})} workers used)")
    return 0
