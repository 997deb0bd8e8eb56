"""Many sites on the Dask cluster of rail_monitor.batch.sites: the same manifest of busy sites on a
local cluster of 1 worker and of 2 workers, in one run (passes per second over all sites, the
cluster's start included, and the speed-up).

Run alone: ros2_ws/run python -m bench.sites [--sites 4] [--passes 20000]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import bench  # noqa: F401  (private DDS domain, one maths thread)
from bench.batch import busy_history
from rail_monitor.bagio.passes_bag import write_passes_bag
from rail_monitor.batch.sites import SiteJob, run_sites
from rail_monitor.site_file import load_parameter_file

Row = tuple[str, str, str]


def rows(values: Mapping[str, Any], site_file: str, sites: int, passes: int) -> list[Row]:
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        histories = []
        for i in range(sites):
            v = {**values, "simulator.seed": 100 + i}
            histories.append(write_passes_bag(busy_history(v, passes), tmp / f"history_{i}", ""))
        seconds = {}
        total = 0
        for workers in (1, 2):
            jobs = [SiteJob(Path(site_file), Path(h), tmp / f"out_{workers}_{i}") for i, h in enumerate(histories)]
            t = time.perf_counter()
            results = run_sites(jobs, workers=workers)
            seconds[workers] = time.perf_counter() - t
            total = sum(r.passes for r in results)
    return [(f"{sites} sites x {passes:,} passes, 1 worker", f"{total / seconds[1]:,.0f} passes/s",
             f"{seconds[1]:.1f} s, the local cluster's start included"),
            (f"{sites} sites x {passes:,} passes, 2 workers", f"{total / seconds[2]:,.0f} passes/s",
             f"{seconds[2]:.1f} s; speed-up x{seconds[1] / seconds[2]:.2f}")]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--sites", type=int, default=4)
    ap.add_argument("--passes", type=int, default=20_000)
    ns = ap.parse_args()
    for what, figure, note in rows(load_parameter_file(ns.site), ns.site, ns.sites, ns.passes):
        print(f"{what:45s} {figure:>20s}  {note}")


if __name__ == "__main__":
    main()
