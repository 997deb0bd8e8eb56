"""The network grinding programme (rail-monitor plan's solver): sites x years solved without a
capacity, and with a capacity of 85 % of that programme's busiest month, in one run.

Run alone: ros2_ws/run python -m bench.plan [--sites 500] [--years 5]
"""

from __future__ import annotations

import argparse

import numpy as np

import bench  # noqa: F401  (private DDS domain, one maths thread)
from rail_monitor.economics.programme import Rules, plan
from rail_monitor.simulation.network import network_outlooks

Row = tuple[str, str, str]


def rows(sites: int, years: int) -> list[Row]:
    outlooks = network_outlooks(sites, 2026)
    free = plan(outlooks, Rules(12 * years, 0))
    peak = int(np.bincount(np.concatenate(free.visits)).max())
    held = plan(outlooks, Rules(12 * years, 0, capacity=int(0.85 * peak)))
    busiest = int(np.bincount(np.concatenate(held.visits)).max())
    return [(f"programme, {sites} sites x {years} years, no capacity", f"{free.seconds:.1f} s",
             f"{free.schedules:,} candidate schedules; busiest month {peak} visits; {free.status.split('(')[0]}"),
            (f"programme, {sites} sites x {years} years, {int(0.85 * peak)} visits a month", f"{held.seconds:.1f} s",
             f"busiest month {busiest}; expected cost x{held.expected_cost.sum() / free.expected_cost.sum():.3f} "
             f"of the unlimited; largest risk {100 * held.risk.max():.1f} %; {held.status.split('(')[0]}")]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sites", type=int, default=500)
    ap.add_argument("--years", type=int, default=5)
    ns = ap.parse_args()
    for what, figure, note in rows(ns.sites, ns.years):
        print(f"{what:55s} {figure:>10s}  {note}")


if __name__ == "__main__":
    main()
