"""Soak: a live graph for a long run under a disk budget (issues 21 and 52).

One process (``--layout one``): ``wayside_monitor`` fed by its pass simulator at a steady rate
(flat hourly profile, ``rate`` chosen for the wanted passes per second) records every topic into a
bag split by size with a retention budget, for ``--minutes``.

Five processes (``--layout five``, issue 52): the launch file's layout (corrugation_estimator,
rolling_noise_predictor, squeal_risk_model, alert_manager, mcap_recorder, each its own process)
fed by pass_simulator in a sixth, on sim time: ``--days`` of simulated traffic at ``--speedup``
times real time (the issue's case: 30 days at 100x, 7.2 hours). This process listens to
/diagnostics: when the simulator has published its last pass and the counts have settled, every
message each node reports sent on a topic must be one the recorder reports recorded on it (the
recorder counts what retention later deleted too), and the passes published must all be recorded.

Every ``--sample-s`` the graph's resident memory (every process) and the bag folder's size on disk
are read; at the end the graph is stopped with SIGINT and every kept file is opened with rosbags
(the folder, through metadata.yaml) and with the mcap library (each file).

Run: ros2_ws/run python -m bench.soak [--layout five --days 30 --speedup 100] [--budget-mib 20]
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

from bench.spun_node import SpunNode
from bench.timing import header, rss_mb

DAY_S = 86_400.0
TRAINS_PER_HOUR = 4.0  # a flat profile: 96 trains a day at any hour


def folder_bytes(folder: Path) -> int:
    """Bytes the folder's files take on disk (whole blocks)."""
    return sum(p.stat().st_blocks * 512 for p in folder.iterdir()) if folder.exists() else 0


def graph_command(site: str, out: Path, minutes: float, per_s: float, budget: int, split: int) -> list[str]:
    rate = per_s / (24 * TRAINS_PER_HOUR / DAY_S)          # simulated time per wall time
    days = 1.1 * minutes * 60.0 * rate / DAY_S              # history long enough for the run
    p = {**_simulator(days, rate, TRAINS_PER_HOUR), "output": str(out), **_recorder(budget, split)}
    return _command("wayside_monitor", site, p)


def _simulator(days: float, rate: float, trains_per_hour: float) -> dict[str, str]:
    hourly = ", ".join([f"{trains_per_hour:.1f}"] * 24)
    return {"simulator.days": f"{days:.6f}", "simulator.trains_per_hour": f"[{hourly}]",
            "rate": f"{rate:.1f}", "progress": "false", "use_sim_time": "true"}


def _recorder(budget: int, split: int) -> dict[str, str]:
    return {"max_bag_size": str(split), "max_total_bytes": str(budget), "chunk_size": str(256 * 1024)}


def _command(exe: str, site: str, params: dict[str, str]) -> list[str]:
    args = [exe, "--ros-args", "--params-file", site, "--log-level", "warn"]
    for k, v in params.items():
        args += ["-p", f"{k}:={v}"]
    return args


def five_process_commands(site: str, out: Path, days: float, speedup: float, trains_per_hour: float, budget: int,
                          split: int) -> list[list[str]]:
    """The launch file's five processes and the simulator feeding them (last), on sim time."""
    from bench.live import MODEL_EXECUTABLES

    sim = {"use_sim_time": "true"}
    return [*(_command(exe, site, sim) for exe in MODEL_EXECUTABLES),
            _command("mcap_recorder", site, {**sim, "output": str(out), **_recorder(budget, split)}),
            _command("pass_simulator", site, {**_simulator(days, speedup, trains_per_hour),
                                              "wait_for_subscribers": str(len(MODEL_EXECUTABLES) + 1)})]


class DiagnosticsListener(SpunNode):
    """The latest /diagnostics values of every node of the graph (a thread of this process)."""

    def __init__(self) -> None:
        from diagnostic_msgs.msg import DiagnosticArray

        from rail_monitor.nodes.qos import DIAGNOSTICS_QOS

        super().__init__("bench_soak")
        self.latest: dict[str, dict[str, str]] = {}
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self._on, DIAGNOSTICS_QOS)
        self.start()

    def _on(self, msg) -> None:
        with self.lock:
            for st in msg.status:
                self.latest[st.name] = {kv.key: kv.value for kv in st.values}

    def counts(self) -> tuple[dict[str, int], dict[str, int], int]:
        """(sent per topic over every node, recorded per topic, passes published by the simulator)."""
        sent: dict[str, int] = {}
        recorded: dict[str, int] = {}
        published = 0
        with self.lock:
            for name, values in self.latest.items():
                for k, v in values.items():
                    if k.startswith("sent "):
                        sent[k[5:]] = sent.get(k[5:], 0) + int(v)
                    elif k.startswith("recorded /"):
                        recorded[k[9:]] = int(v)
                if name.endswith("pass_simulator"):
                    published = int(values.get("published", 0))
        return sent, recorded, published


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


def _settled(listener: DiagnosticsListener, sim: subprocess.Popen, timeout_s: float) -> tuple[dict, dict, int]:
    """The counts once the simulator is done and nothing has moved for 5 s (or timeout_s passed)."""
    t0, last, since = time.monotonic(), None, time.monotonic()
    while time.monotonic() - t0 < timeout_s:
        time.sleep(1.0)
        now = listener.counts()
        if now != last:
            last, since = now, time.monotonic()
        elif sim.poll() is not None and time.monotonic() - since >= 5.0:
            break
    return last or ({}, {}, 0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--layout", choices=("one", "five"), default="one")
    ap.add_argument("--minutes", type=float, default=30.0, help="one: how long to run")
    ap.add_argument("--passes-per-s", type=float, default=10.0, help="one: the pass rate")
    ap.add_argument("--days", type=float, default=30.0, help="five: simulated days of traffic")
    ap.add_argument("--speedup", type=float, default=100.0, help="five: simulated time per wall time")
    ap.add_argument("--trains-per-hour", type=float, default=TRAINS_PER_HOUR, help="five: the flat traffic")
    ap.add_argument("--warm-days", type=float, default=40.0,
                    help="five: simulated days before the memory trend is taken (the stores bounded by the "
                         "history window and by count fill first)")
    ap.add_argument("--budget-mib", type=float, default=20.0)
    ap.add_argument("--split-mib", type=float, default=2.0)
    ap.add_argument("--sample-s", type=float, default=10.0)
    ap.add_argument("--out", default="out/soak.md")
    ns = ap.parse_args()
    header("soak")
    budget, split = int(ns.budget_mib * 2**20), int(ns.split_mib * 2**20)
    env = dict(os.environ)  # the bench package's: a private domain, localhost discovery, one maths thread
    five = ns.layout == "five"
    minutes = ns.days * DAY_S / ns.speedup / 60.0 if five else ns.minutes
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / "soak"
        log = Path(tmp) / "graph.log"
        listener = DiagnosticsListener() if five else None
        commands = (five_process_commands(ns.site, bag, ns.days, ns.speedup, ns.trains_per_hour, budget, split)
                    if five else [graph_command(ns.site, bag, ns.minutes, ns.passes_per_s, budget, split)])
        with log.open("w") as err:
            procs = [subprocess.Popen(c, stdout=subprocess.DEVNULL, stderr=err, env=env) for c in commands]
        t0 = time.monotonic()
        samples: list[tuple[float, float, int]] = []  # (minutes, RSS MB of the graph, folder bytes)
        each: list[list[float]] = []  # RSS MB of each process of the graph, at the same samples
        graph = procs[:-1] if five else procs  # the simulator ends by itself: not part of the graph's memory
        running = (lambda: procs[-1].poll() is None) if five else (lambda: procs[0].poll() is None)
        while time.monotonic() - t0 < (minutes * 60.0 if not five else 2 * minutes * 60.0 + 600) and running():
            time.sleep(ns.sample_s)
            if all(p.poll() is None for p in graph):
                each.append([rss_mb(p.pid) for p in graph])
                samples.append(((time.monotonic() - t0) / 60.0, sum(each[-1]), folder_bytes(bag)))
        counts = _settled(listener, procs[-1], 120.0) if five else None
        for p in procs:
            if p.poll() is None:
                p.send_signal(signal.SIGINT)
        rcs = [p.wait(timeout=120) for p in procs]
        if listener is not None:
            listener.close()
        wall_min = (time.monotonic() - t0) / 60.0
        if not bag.exists():
            raise SystemExit(f"no bag recorded; the graph's log:\n{log.read_text()[-3000:]}")
        messages, files = check_kept(bag)
        final = folder_bytes(bag)
        errors = [line for line in log.read_text().splitlines() if "Traceback" in line or line.startswith("error")]
    t, rss, size = (np.array(c) for c in zip(*samples, strict=True))
    warm = t >= (ns.warm_days * DAY_S / ns.speedup / 60.0 if five else min(5.0, t[-1] / 3))  # after the stores fill
    slope = np.polyfit(t[warm], rss[warm], 1)[0] if warm.sum() > 2 else float("nan")
    late = t >= 2 * t[-1] / 3
    late_slope = np.polyfit(t[late], rss[late], 1)[0] if late.sum() > 2 else float("nan")
    per_day = ns.speedup / DAY_S * 60.0  # simulated days per wall minute
    names = [c[0] for c in commands[:len(graph)]]
    by_process = ", ".join(f"{name} {np.polyfit(t[warm], col[warm], 1)[0] / per_day:+.3f}"
                           for name, col in zip(names, np.array(each).T, strict=True)) if warm.sum() > 2 else ""
    what = (f"{ns.days:g} simulated days at {ns.speedup:g}x ({24 * ns.trains_per_hour:g} trains a day), five "
            f"processes and the simulator; memory trend after {ns.warm_days:g} simulated days" if five
            else f"{ns.passes_per_s:g} passes per second, wayside_monitor")
    rows = [("run", f"{wall_min:.1f} min", f"{what}; exit codes {rcs}; {len(errors)} error lines"),
            ("RSS of the graph after warm-up / at the end", f"{rss[warm][0]:.0f} / {rss[-1]:.0f} MB",
             f"trend {60 * slope:+.1f} MB/hour over {t[warm][-1] - t[warm][0]:.1f} min, {60 * late_slope:+.1f} "
             f"MB/hour over the last third; peak {rss.max():.0f} MB"
             + (f"; per simulated day {slope / per_day:+.3f} MB ({by_process})" if five else "")),
            ("bag on disk, largest sample / budget", f"{size.max() / 2**20:.2f} / {ns.budget_mib:g} MiB",
             f"final {final / 2**20:.2f} MiB; {len(samples)} samples, every {ns.sample_s:g} s"),
            ("kept files", f"{files}", f"{messages:,} messages read by rosbags through metadata.yaml; "
             "each file read whole by the mcap library")]
    if counts is not None:
        sent, recorded, published = counts
        passes_topic = next((t for t in recorded if t.endswith("/train_pass")), "")
        lost = {t: n - recorded.get(t, 0) for t, n in sent.items() if n != recorded.get(t, 0)}
        rows.append(("messages sent / recorded", f"{sum(sent.values()):,} / "
                     f"{sum(recorded.get(t, 0) for t in sent):,}",
                     f"{len(sent)} topics; differing: {lost or 'none'}; passes published {published:,}, recorded "
                     f"{recorded.get(passes_topic, 0):,}"))
    text = "| soak | figure | note |\n| --- | ---: | --- |\n" + "\n".join(f"| {a} | {b} | {c} |" for a, b, c in rows)
    print(text)
    Path(ns.out).parent.mkdir(parents=True, exist_ok=True)
    Path(ns.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
