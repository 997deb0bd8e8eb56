"""Batch mode: passes per second at 1e4, 1e5 and 1e6 simulated passes, and equality with the live graph.

Histories come from the simulator at a busy site: the site's daily traffic profile scaled to
about 100,000 train passes a year, over as many days as the size needs. The site's tables
(rail receptance, growth and noise transfer tables) are built, and the compiled kernels loaded,
once per process before timing and reported as set-up.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from bench.timing import first_touch_s, peak_rss_mb
from rail_monitor.batch.bag import run_to_bag
from rail_monitor.batch.run import run_models
from rail_monitor.core.passes import PassTable
from rail_monitor.core.simulator_params import simulator_config
from rail_monitor.core.site import site_from_values
from rail_monitor.core.timeutil import NS_PER_DAY, format_iso_ns, parse_iso_ns
from rail_monitor.engine.result import SiteOutputs
from rail_monitor.simulation.simulator import simulate

BUSY_YEAR = 100_000  # train passes a year at a busy site


def busy_values(values: Mapping[str, Any], passes: int) -> dict[str, Any]:
    """The site's parameters with the simulator set for about ``passes`` at BUSY_YEAR a year."""
    out = dict(values)
    profile = np.asarray(values["simulator.trains_per_hour"], float)
    per_day = BUSY_YEAR / 365.0
    out["simulator.trains_per_hour"] = (profile * per_day / profile.sum()).tolist()
    out["simulator.days"] = passes / per_day
    return out


def busy_history(values: Mapping[str, Any], passes: int) -> PassTable:
    v = busy_values(values, passes)
    return simulate(site_from_values(v), simulator_config(v))


SET_UP_PASSES = 1_000  # a few days: every kernel is called (a history of hours may hold no pass)


def set_up_s(values: Mapping[str, Any]) -> float:
    """Wall time of a first, short batch run: the site's tables (cached for the process) and the
    compiled kernels (loaded from numba's cache, or compiled the first time on a machine) [s]."""
    table = busy_history(values, SET_UP_PASSES)
    t = time.perf_counter()
    run_models(table, values)
    return time.perf_counter() - t


def timed(values: Mapping[str, Any], passes: int, threads: int = 0) -> tuple[int, float, SiteOutputs]:
    table = busy_history(values, passes)
    t = time.perf_counter()
    r = run_models(table, values, threads=threads)
    return len(table), time.perf_counter() - t, r


def live_equality(bag: str, values: Mapping[str, Any]) -> dict[str, float]:
    """Largest differences between a live graph's bag and batch mode on the passes it recorded:
    relative for corrugation amplitudes, absolute in dB for levels; and alert events live - batch."""
    from rail_monitor.report.run_data import load_run

    run = load_run(bag)
    r = run_models(run.passes, values)
    out = {"states": float(len(run.states["amplitude_m"]) - len(r.trajectory))}
    out["corrugation_rel"] = float(np.max(np.abs(run.states["amplitude_m"] / r.trajectory.amplitude - 1.0)))
    out["noise_db"] = max(float(np.max(np.abs(run.noise[m]["lpaeq_tp_dba"] - r.noise[m].lpaeq_tp_dba)))
                          for m in r.noise)
    live, offline = run.squeal["level_dba"], r.squeal["level_dba"]  # NaN: no squeal
    out["squeal_db"] = float(np.max(np.abs(np.nan_to_num(live) - np.nan_to_num(offline)), initial=0.0)
                             if np.array_equal(np.isnan(live), np.isnan(offline)) else np.inf)
    out["alerts"] = float(len(run.alerts) - len(r.alerts))
    return out


def busy_chunks(values: Mapping[str, Any], passes: int, chunk: int) -> Iterator[PassTable]:
    """About ``passes`` busy-site passes as consecutive simulated periods of about ``chunk`` passes
    each (a seed per period), in time order: a history never held whole."""
    v = busy_values(values, chunk)
    start = parse_iso_ns(str(values["simulator.start_time"]))
    for k in range(max(1, round(passes / chunk))):
        t0 = start + round(k * v["simulator.days"] * NS_PER_DAY)
        w = {**v, "simulator.seed": 1000 + k, "simulator.start_time": format_iso_ns(t0)}
        yield simulate(site_from_values(w), simulator_config(w))


def streamed(values: Mapping[str, Any], passes: int, chunk: int = 5_000) -> tuple[int, float, float]:
    """rail-monitor batch's streamed path (app.batch_bag.run_to_bag) over a simulated history recorded
    to a temporary bag: (passes, wall time [s], peak RSS of this process [MB]). Run it in a fresh
    process for its own peak."""
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        n = run_to_bag(busy_chunks(values, passes, chunk), values, Path(tmp) / "bag", "site").passes
        return n, time.perf_counter() - t, peak_rss_mb()


def streamed_in_subprocess(site: str, passes: int) -> tuple[int, float, float]:
    """streamed() in a fresh interpreter (its peak memory is its own)."""
    done = subprocess.run([sys.executable, "-m", "bench.batch", "--site", site, "--streamed", str(passes)],
                          capture_output=True, text=True, check=True)
    n, t, mb = done.stdout.split()[-3:]
    return int(n), float(t), float(mb)


def on_cores_in_subprocess(site: str, passes: int, cores: int) -> tuple[int, float]:
    """timed() in a fresh interpreter held to the first ``cores`` of this process's CPUs, with as
    many threads: (passes, seconds)."""
    done = subprocess.run([sys.executable, "-m", "bench.batch", "--site", site, "--sizes", str(passes), "--cores",
                           str(cores)], capture_output=True, text=True, check=True)
    line = done.stdout.strip().splitlines()[-1].split()
    return int(line[0].replace(",", "")), float(line[2])


def main() -> None:
    import argparse
    import os

    from rail_monitor.site_file import load_parameter_file

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--sizes", default="1e4,1e5,1e6")
    ap.add_argument("--cores", type=int, default=0, help="hold the process to this many CPUs and use as many "
                    "threads (default: every CPU)")
    ap.add_argument("--streamed", type=float, help="only the streamed run of this many passes; prints passes, "
                    "seconds and peak RSS [MB]")
    ap.add_argument("--repeat", type=int, default=1, help="run each size this many times in the process (the "
                    "first run also pays the first touch of its memory)")
    ns = ap.parse_args()
    values = load_parameter_file(ns.site)
    if ns.cores:
        os.sched_setaffinity(0, sorted(os.sched_getaffinity(0))[:ns.cores])
    if ns.streamed:
        print(*streamed(values, int(ns.streamed)))
        return
    fresh, again = first_touch_s()
    print(f"filling 256 MB new to this process: {fresh:.2f} s; again, reused: {again:.2f} s")
    print(f"set-up (site tables, kernels; once per process): {set_up_s(values):.2f} s")
    for size in (int(float(x)) for x in ns.sizes.split(",")):
        for _ in range(ns.repeat):
            n, t, _ = timed(values, size, ns.cores)
            print(f"{n:>9,} passes: {t:8.2f} s = {n / t:9.0f} passes/s (peak RSS so far {peak_rss_mb():.0f} MB)")


if __name__ == "__main__":
    main()
