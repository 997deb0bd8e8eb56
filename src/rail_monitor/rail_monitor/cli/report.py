"""rail-monitor report: the summary of a recorded run and its report folder."""

from __future__ import annotations

import argparse

from rail_monitor.cli.common import add_site_option, print_report
from rail_monitor.core.errors import RailMonitorError


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("report", help="print the summary of a recorded run and write its report folder "
                       "(PNG plots, index.html)")
    s.add_argument("bag", help="bag recorded by the graph or by batch")
    add_site_option(s, default="the site stored in the bag")
    s.add_argument("--out", help="report folder (default: <bag>_report)")
    s.add_argument("--listen", type=int, default=3, help="the loudest passes made audible in the report, beside "
                   "their recordings where a station kept them (0: none) (default: 3)")
    s.add_argument("--audio-archive", help="a noise_station's audio archive folder (default: the site's "
                   "station.archive_folder)")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    if not 0 <= ns.listen <= 100:
        raise RailMonitorError(f"--listen must be between 0 and 100 passes, not {ns.listen}")
    print_report(ns.bag, ns.site, ns.out, ns.listen, ns.audio_archive)
    return 0
