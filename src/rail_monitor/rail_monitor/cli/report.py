"""rail-monitor report: the summary of a recorded run and its report folder."""

from __future__ import annotations

import argparse

from rail_monitor.cli.common import add_site_option, print_report


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("report", help="print the summary of a recorded run and write its report folder "
                       "(PNG plots, index.html)")
    s.add_argument("bag", help="bag recorded by the graph or by batch")
    add_site_option(s, default="the site stored in the bag")
    s.add_argument("--out", help="report folder (default: <bag>_report)")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    print_report(ns.bag, ns.site, ns.out)
    return 0
