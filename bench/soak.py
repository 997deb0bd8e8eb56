"""Soak: the recorder of a live graph for a long run under a disk budget (issue 21).

``wayside_monitor`` in its own process, fed by its pass simulator at a steady rate (flat hourly
profile, ``rate`` chosen for the wanted passes per second), records every topic into a bag split
by size with a retention budget. Every ``--sample-s`` the process's resident memory and the bag
folder's size on disk are read; at the end the graph is stopped with SIGINT and every kept file
is opened with rosbags (the folder, through metadata.yaml) and with the mcap library (each file).

Run: ros2_ws/run python -m bench.soak [--minutes 30] [--passes-per-s 10] [--budget-mib 20]
Writes the figures to out/soak.md. Not part of CI (it runs for as long as asked).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

from bench.timing import header, rss_mb

DAY_S = 86_400.0
TRAINS_PER_HOUR = 4.0  # a flat profile: 96 trains a day at any hour


def folder_bytes(folder: Path) -> int:
    """Bytes the folder's files take on disk (whole blocks)."""
    return sum(p.stat().st_blocks * 512 for p in folder.iterdir()) if folder.exists() else 0


def graph_command(site: str, out: Path, minutes: float, per_s: float, budget: int, split: int) -> list[str]:
    rate = per_s / (24 * TRAINS_PER_HOUR / DAY_S)          # simulated time per wall time
    days = 1.1 * minutes * 60.0 * rate / DAY_S              # history long enough for the run
    p = {"simulator.days": f"{days:.1f}", "simulator.trains_per_hour": f"[{', '.join(['4.0'] * 24)}]",
         "rate": f"{rate:.1f}", "progress": "false", "output": str(out), "use_sim_time": "true",
         "max_bag_size": str(split), "max_total_bytes": str(budget), "chunk_size": str(256 * 1024)}
    args = ["wayside_monitor", "--ros-args", "--params-file", site, "--log-level", "warn"]
    for k, v in p.items():
        args += ["-p", f"{k}:={v}"]
    return args


def check_kept(folder: Path) -> tuple[int, int]:
    """(messages rosbags reads through metadata.yaml, files the mcap library reads whole)."""
    with AnyReader([folder]) as reader:
        n = sum(1 for _ in reader.messages())
    files = 0
    for f in sorted(folder.glob("*.mcap")):
        with f.open("rb") as stream:
            reader = make_reader(stream)
            reader.get_summary()
            sum(1 for _ in reader.iter_messages())
        files += 1
    return n, files


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--passes-per-s", type=float, default=10.0)
    ap.add_argument("--budget-mib", type=float, default=20.0)
    ap.add_argument("--split-mib", type=float, default=2.0)
    ap.add_argument("--sample-s", type=float, default=10.0)
    ap.add_argument("--out", default="out/soak.md")
    ns = ap.parse_args()
    header("soak")
    budget, split = int(ns.budget_mib * 2**20), int(ns.split_mib * 2**20)
    env = dict(os.environ)  # the bench package's: a private domain, localhost discovery, one maths thread
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / "soak"
        log = Path(tmp) / "graph.log"
        with log.open("w") as err:
            proc = subprocess.Popen(graph_command(ns.site, bag, ns.minutes, ns.passes_per_s, budget, split),
                                    stdout=subprocess.DEVNULL, stderr=err, env=env)
        t0 = time.monotonic()
        samples: list[tuple[float, float, int]] = []  # (minutes, RSS MB, folder bytes)
        while time.monotonic() - t0 < ns.minutes * 60.0 and proc.poll() is None:
            time.sleep(ns.sample_s)
            if proc.poll() is None:
                samples.append(((time.monotonic() - t0) / 60.0, rss_mb(proc.pid), folder_bytes(bag)))
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        rc = proc.wait(timeout=120)
        wall_min = (time.monotonic() - t0) / 60.0
        messages, files = check_kept(bag)
        final = folder_bytes(bag)
        errors = [line for line in log.read_text().splitlines() if "Traceback" in line or line.startswith("error")]
    t, rss, size = (np.array(c) for c in zip(*samples, strict=True))
    warm = t >= min(5.0, t[-1] / 3)  # after start-up and the first splits
    slope = np.polyfit(t[warm], rss[warm], 1)[0] if warm.sum() > 2 else float("nan")
    late = t >= 2 * t[-1] / 3  # the noise predictor's 10,000 kept states fill in the first 17 min at 10/s
    late_slope = np.polyfit(t[late], rss[late], 1)[0] if late.sum() > 2 else float("nan")
    rows = [("run", f"{wall_min:.1f} min", f"exit {rc}; {len(errors)} error lines"),
            ("passes per second asked", f"{ns.passes_per_s:g}", "every topic recorded"),
            ("RSS after warm-up / at the end", f"{rss[warm][0]:.0f} / {rss[-1]:.0f} MB",
             f"trend {slope:+.2f} MB/min over {t[warm][-1] - t[warm][0]:.1f} min, {late_slope:+.2f} MB/min over "
             f"the last third; peak {rss.max():.0f} MB"),
            ("bag on disk, largest sample / budget", f"{size.max() / 2**20:.2f} / {ns.budget_mib:g} MiB",
             f"final {final / 2**20:.2f} MiB; {len(samples)} samples, every {ns.sample_s:g} s"),
            ("kept files", f"{files}", f"{messages:,} messages read by rosbags through metadata.yaml; "
             "each file read whole by the mcap library")]
    text = "| soak | figure | note |\n| --- | ---: | --- |\n" + "\n".join(f"| {a} | {b} | {c} |" for a, b, c in rows)
    print(text)
    Path(ns.out).parent.mkdir(parents=True, exist_ok=True)
    Path(ns.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
