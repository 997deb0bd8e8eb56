"""Timing helper shared by the benchmarks."""

from __future__ import annotations

import argparse
import platform
import time
from collections.abc import Callable

import numpy as np


def best_of(fn: Callable[[], object], repeat: int = 5) -> float:
    """Shortest wall time of repeat calls [s] (the least disturbed by other load)."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def parser(doc: str) -> argparse.ArgumentParser:
    """The command line of a benchmark (its docstring's first paragraph) with --site."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml", help="site parameter file")
    return ap


def header(name: str) -> None:
    """The first line of a benchmark's output: what ran, where."""
    print(f"# {name} benchmark, {platform.node()}, {platform.processor() or platform.machine()}, "
          f"numpy {np.__version__}")


def rss_mb(pid: int | str = "self") -> float:
    """Resident memory of a process now [MB] (VmRSS)."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError(f"no VmRSS for process {pid}")


def peak_rss_mb(pid: int | str = "self") -> float:
    """Peak resident memory of a process [MB] (VmHWM: its own, unlike getrusage's ru_maxrss,
    which Linux carries over exec from whatever ran before in the process)."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError(f"no VmHWM for process {pid}")


def first_touch_s(mb: int = 256) -> tuple[float, float]:
    """Wall time to fill mb MB this process has not used, then the same size again after freeing
    it [s]. Where the first is much longer, memory new to the machine is dear (a virtual machine's
    host maps each page at its first use): a first run that allocates much pays it, a second run
    in the same process reuses its memory."""
    times = []
    for _ in range(2):
        t = time.perf_counter()
        a = np.ones(mb * 2**20 // 8)
        times.append(time.perf_counter() - t)
        del a
    return times[0], times[1]
