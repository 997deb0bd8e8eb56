"""The live graph as a site runs it: start-up, idle CPU, CPU and latency with passes arriving one at a time.

The graph is the separate-process layout of the launch file (corrugation_estimator,
rolling_noise_predictor, squeal_risk_model, alert_manager, mcap_recorder, each its own process,
on wall time), fed by a probe node in this process that publishes sample passes stamped now and
listens to the outputs. Latency of a pass: from its publication to the arrival of its last output
(the rolling noise of both models), as the probe sees them. CPU: user + system time of the graph's
processes over the period, as a share of one core. Start-up: wayside_monitor (the one-process graph)
on a one-pass history, from its spawn to the probe's receipt of its first output, with its
resident memory then (its replayer waits for the probe's subscription, as for its own nodes').
The same idle and rate measurements are then made of the no-op graph in the separate-process layout
(bench.bare_graph's stand-ins, each its own process, and the real recorder: what rclpy and DDS cost
with no model; its outputs carry a fixed train id, so it has no latency), of the one-process
graph as a site would run it with its own detector driver (wayside_monitor with listen:=true, the
probe publishing the passes), and of the no-op graph in that one-process layout.
Both graphs' corrugation estimators resume from a checkpoint holding what a busy site's keeps
(``--kept-days`` of its traffic up to now, default the site's corrugation.history_days), so a
pass costs what it costs at a site that has run for a while; 0: an empty state.

Run alone: ros2_ws/run python -m bench.live [--rate 100 --seconds 10]
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import bench  # noqa: F401  (private DDS domain, one maths thread)
from bench.spun_node import SpunNode
from bench.timing import rss_mb

MODEL_EXECUTABLES = ("corrugation_estimator", "rolling_noise_predictor", "squeal_risk_model", "alert_manager")
TICKS = os.sysconf("SC_CLK_TCK")
BUSY_YEAR_TEXT = "about 100,000 passes a year, bench.batch's busy site"


def cpu_s(pid: int) -> float:
    """User + system CPU time of a process [s]."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICKS


class Probe(SpunNode):
    """A node publishing TrainPass and timing the outputs of each pass (wall clock, monotonic)."""

    def __init__(self, passes: Any) -> None:
        from rail_monitor.messages.fields import train_pass_fields
        from rail_monitor.nodes.convert import TOPICS, to_msg

        super().__init__("bench_probe")
        cls, qos = TOPICS["train_pass"]
        self.pub = self.node.create_publisher(cls, "train_pass", qos)
        self._to_msg, self._fields, self._cls = to_msg, train_pass_fields, cls
        self.passes = passes
        self.sent: dict[str, float] = {}
        self.outputs: dict[str, list[float]] = {}
        self.first_output = 0.0
        for name in ("noise/rolling", "noise/squeal", "corrugation/state"):
            c, q = TOPICS[name]
            self.node.create_subscription(c, name, lambda m, n=name: self._on_output(n, m), q)
        # Subscribed to train_pass too, so a replayer waiting for its subscribers waits for the probe.
        self.node.create_subscription(cls, "train_pass", lambda m: None, qos)
        self.start()

    def _on_output(self, topic: str, msg: Any) -> None:
        now = time.monotonic()
        with self.lock:
            self.first_output = self.first_output or now
            if topic == "noise/rolling":
                self.outputs.setdefault(msg.train_id, []).append(now)

    def subscribers(self) -> int:
        return self.pub.get_subscription_count()

    def send(self, i: int) -> str:
        """Publish sample pass i stamped now, under a fresh train id."""
        row = self.passes.row(i % len(self.passes))
        row["stamp_ns"] = time.time_ns()
        row["train_id"] = f"probe-{len(self.sent)}"
        msg = self._to_msg(self._cls, self._fields(row, "curve_250"))
        with self.lock:
            self.sent[row["train_id"]] = time.monotonic()
        self.pub.publish(msg)
        return row["train_id"]

    def latencies_ms(self, ids: list[str], models: int = 2) -> np.ndarray:
        """Per pass: publication to its last rolling noise output [ms] (NaN: incomplete)."""
        with self.lock:
            return np.array([1e3 * (self.outputs[t][models - 1] - self.sent[t])
                             if len(self.outputs.get(t, [])) >= models else np.nan for t in ids])



def _spawn(exe: str | list[str], site: str, *params: str) -> subprocess.Popen:
    """An executable (or a command line) with the site's parameters file and params (NAME:=VALUE)."""
    args = [*([exe] if isinstance(exe, str) else exe), "--ros-args", "--params-file", site, "--log-level", "warn"]
    for p in params:
        args += ["-p", p]
    return subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def start_up(site: str, probe: Probe, source: str, timeout_s: float = 60.0) -> dict[str, float]:
    """wayside_monitor on a one-pass history: spawn to the probe's first output [s], its CPU time
    [s] and resident memory [MB] then."""
    with tempfile.TemporaryDirectory() as tmp:
        probe.first_output = 0.0
        t0 = time.monotonic()
        proc = _spawn("wayside_monitor", site, f"source:={source}", f"output:={Path(tmp) / 'bag'}",
                      "progress:=false", "wait_for_subscribers:=3")  # site_engine, recorder, probe
        try:
            while not probe.first_output and time.monotonic() - t0 < timeout_s and proc.poll() is None:
                time.sleep(0.002)
            seconds = probe.first_output - t0 if probe.first_output else float("nan")
            cpu, mem = (cpu_s(proc.pid), rss_mb(proc.pid)) if proc.poll() is None else (float("nan"),) * 2
        finally:
            proc.wait(timeout=timeout_s)
    return {"seconds": seconds, "cpu_s": cpu, "rss_mb": mem}


def start_up_listening(site: str, probe: Probe, timeout_s: float = 60.0) -> dict[str, float]:
    """wayside_monitor listen:=true, as a site runs it behind a detector's driver: spawn to the
    first output of one pass the probe sends once site_engine and the recorder subscribe [s]
    (no replayer, so no settling of the graph), its CPU time [s] and resident memory [MB] then."""
    with tempfile.TemporaryDirectory() as tmp:
        probe.first_output = 0.0
        t0 = time.monotonic()
        proc = _spawn("wayside_monitor", site, "listen:=true", f"output:={Path(tmp) / 'bag'}")
        try:
            while probe.subscribers() < 3 and time.monotonic() - t0 < timeout_s:  # engine, recorder, probe
                time.sleep(0.002)
            probe.send(0)
            while not probe.first_output and time.monotonic() - t0 < timeout_s and proc.poll() is None:
                time.sleep(0.002)
            seconds = probe.first_output - t0 if probe.first_output else float("nan")
            cpu, mem = (cpu_s(proc.pid), rss_mb(proc.pid)) if proc.poll() is None else (float("nan"),) * 2
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(timeout=timeout_s)
    return {"seconds": seconds, "cpu_s": cpu, "rss_mb": mem}


def busy_checkpoint(site: str, days: float, path: Path) -> int:
    """Write to path the corrugation state of a busy site (bench.batch's) after ``days`` of traffic
    ending a minute ago, as the estimator node checkpoints it; returns the passes it keeps."""
    from bench.batch import BUSY_YEAR, busy_history
    from rail_monitor.batch.run import run_models
    from rail_monitor.core.timeutil import NS_PER_DAY, NS_PER_S, format_iso_ns
    from rail_monitor.engine.checkpoint import save
    from rail_monitor.site_file import load_parameter_file

    values = load_parameter_file(site)
    start_ns = time.time_ns() - round(days * NS_PER_DAY) - 60 * NS_PER_S
    history = busy_history({**values, "simulator.start_time": format_iso_ns(start_ns)}, round(days * BUSY_YEAR / 365))
    est = run_models(history, values).estimator
    save(est, path)
    return len(est.kept)


def live_graph(site: str, probe: Probe, rates: list[float], seconds: float, idle_s: float,
               layout: str = "separate", state: Path | None = None) -> dict[str, Any]:
    """A graph's idle CPU, then per rate its CPU share and latency percentiles. layout: "separate"
    (a process per node, as the launch file), "one" (wayside_monitor listening: site_engine),
    "one-nodes" (the same with the four model nodes, models:=nodes), "bare" (the
    separate layout with bench.bare_graph's no-op stand-ins for the models and the real recorder)
    or "bare-one" (those stand-ins and the real recorder in one process, listening).
    state: a checkpoint the estimator resumes from (copied: the node writes its own)."""
    timed = not layout.startswith("bare")  # the stand-ins' outputs carry a fixed train id: no latency to time
    with tempfile.TemporaryDirectory() as tmp:
        bag = f"output:={Path(tmp) / 'bag'}"
        resume = []
        if state is not None:
            shutil.copy(state, Path(tmp) / "state.npz")
            # Named for the node: the site file's section for it wins over a parameter for every node.
            holder = "site_engine" if layout == "one" else "corrugation_estimator"  # one-nodes: the four
            resume = [f"{holder}:checkpoint_path:={Path(tmp) / 'state.npz'}"]
        if layout in ("one", "one-nodes"):
            models = ["models:=nodes"] if layout == "one-nodes" else []
            procs = [_spawn("wayside_monitor", site, "listen:=true", bag, *resume, *models)]
            names = ["wayside_monitor"]
        elif layout == "bare-one":
            procs = [_spawn([sys.executable, "-m", "bench.bare_graph", "wayside_monitor", "--site", site], site,
                            "listen:=true", bag)]
            names = ["wayside_monitor"]
        elif layout == "bare":
            procs = [subprocess.Popen([sys.executable, "-m", "bench.bare_graph", exe, "--site", site],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                     for exe in MODEL_EXECUTABLES]
            procs.append(_spawn("mcap_recorder", site, bag))
            names = [*MODEL_EXECUTABLES, "mcap_recorder"]
        else:
            procs = [_spawn(exe, site, *(resume if exe == "corrugation_estimator" else []))
                     for exe in MODEL_EXECUTABLES]
            procs.append(_spawn("mcap_recorder", site, bag))
            names = [*MODEL_EXECUTABLES, "mcap_recorder"]
        try:
            t0 = time.monotonic()
            # train_pass subscribers: the models (site_engine alone in one process) and the recorder
            models = 1 if layout in ("one", "bare-one") else len(MODEL_EXECUTABLES)
            while probe.subscribers() < models + 2 and time.monotonic() - t0 < 60:
                time.sleep(0.05)
            warm = [probe.send(i) for i in range(3)]  # first outputs: lazy set-up paid before measuring
            while timed and np.isnan(probe.latencies_ms(warm)).any() and time.monotonic() - t0 < 120:
                time.sleep(0.05)
            time.sleep(2.0)
            out: dict[str, Any] = {"processes": len(procs)}
            idle0 = [cpu_s(p.pid) for p in procs]
            time.sleep(idle_s)
            idle = [(cpu_s(p.pid) - c) / idle_s for p, c in zip(procs, idle0, strict=True)]
            out["idle_core"], out["idle_per_process"] = sum(idle), dict(zip(names, idle, strict=True))
            n = 3
            for rate in rates:
                ids, per0, t_start = [], [cpu_s(p.pid) for p in procs], time.monotonic()
                count = max(int(rate * seconds), 1)
                for k in range(count):
                    delay = t_start + k / rate - time.monotonic()
                    if delay > 0:
                        time.sleep(delay)
                    ids.append(probe.send(n))
                    n += 1
                t_end = time.monotonic() + (10.0 if timed else 0.03)  # no-op: a pass's few ms
                while (not timed or np.isnan(probe.latencies_ms(ids)).any()) and time.monotonic() < t_end:
                    time.sleep(0.01)
                wall = time.monotonic() - t_start
                lat = probe.latencies_ms(ids) if timed else np.zeros(len(ids))
                per = [(cpu_s(p.pid) - c) / wall for p, c in zip(procs, per0, strict=True)]
                out[rate] = {"core": sum(per), "per_process": dict(zip(names, per, strict=True)), "passes": count,
                             "p50_ms": float(np.nanpercentile(lat, 50)), "p95_ms": float(np.nanpercentile(lat, 95)),
                             "lost": int(np.isnan(lat).sum())}
                time.sleep(1.0)
        finally:
            for p in procs:
                p.send_signal(signal.SIGINT)  # wayside_monitor finishes its bag on SIGINT, as the others
            for p in procs:
                p.wait(timeout=60)
    return out


def rows(site: str, source: str, rates: list[float], seconds: float, idle_s: float,
         kept_days: float | None = None) -> list[tuple[str, str, str]]:
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.corrugation.config import corrugation_config
    from rail_monitor.nodes.pass_source import GRAPH_SETTLE_S
    from rail_monitor.site_file import load_parameter_file

    passes = read_passes(source).sorted()
    probe = Probe(passes.take(slice(0, 2000)))
    try:
        with tempfile.TemporaryDirectory() as tmp:
            one = write_passes_bag(passes.take(slice(0, 1)), Path(tmp) / "one", "curve_250")
            cold = start_up(site, probe, str(one))  # the site's tables built, unless cached before
            s = start_up(site, probe, str(one))
            heard = start_up_listening(site, probe)
            if kept_days is None:
                kept_days = corrugation_config(load_parameter_file(site)).history_days
            state, kept = None, 0
            if kept_days > 0:
                state = Path(tmp) / "busy.npz"
                kept = busy_checkpoint(site, kept_days, state)
            g = live_graph(site, probe, rates, seconds, idle_s, state=state)
            bare = live_graph(site, probe, rates, seconds, idle_s, layout="bare")
            one = live_graph(site, probe, rates, seconds, idle_s, layout="one", state=state)
            one_nodes = live_graph(site, probe, rates, seconds, idle_s, layout="one-nodes", state=state)
            bare_one = live_graph(site, probe, rates, seconds, idle_s, layout="bare-one")
    finally:
        probe.close()
    out = [("wayside_monitor start-up to first output", f"{s['seconds']:.2f} s",
            f"{s['cpu_s']:.1f} CPU-s, {s['rss_mb']:.0f} MB resident then; a one-pass history, the site's tables "
            f"from the disk cache (the run before: {cold['seconds']:.2f} s); includes the {GRAPH_SETTLE_S:g} s its "
            "replayer lets the graph settle when another process listens (the probe)"),
           ("wayside_monitor start-up to first output, listening", f"{heard['seconds']:.2f} s",
            f"{heard['cpu_s']:.1f} CPU-s, {heard['rss_mb']:.0f} MB resident then; listen:=true, as behind a "
            "detector's driver: one pass sent once site_engine and the recorder subscribe (no replayer, no "
            "settling)"),
           ("corrugation state the graphs resume from", f"{kept:,} passes kept",
            f"{kept_days:g} days of a busy site's traffic ({BUSY_YEAR_TEXT}) up to now" if kept else "empty"),
           (f"live graph idle ({g['processes']} processes)", f"{100 * g['idle_core']:.1f} % of a core",
            f"over {idle_s:g} s with no passes; by process: "
            + ", ".join(f"{name} {100 * c:.1f} %" for name, c in g["idle_per_process"].items()))]
    for rate in rates:
        r = g[rate]
        out.append(_rate_row(f"live graph, {rate:g} passes/s arriving one at a time", r, "; by process: "
                             + ", ".join(f"{name} {100 * c:.0f} %" for name, c in r["per_process"].items())))
    out += [_rate_row(f"no-op graph, {rate:g} passes/s arriving one at a time", bare[rate], "; the same "
                      "processes, topics, message sizes, QoS, executor and recorder, the models' callbacks only "
                      "publishing (bench.bare_graph); by process: "
                      + ", ".join(f"{name} {100 * c:.0f} %" for name, c in bare[rate]["per_process"].items()),
                      latency=False) for rate in rates]
    out.append(("one-process graph idle (wayside_monitor listen:=true)", f"{100 * one['idle_core']:.1f} % of a core",
                f"over {idle_s:g} s with no passes"))
    out += [_rate_row(f"one-process graph, {rate:g} passes/s arriving one at a time", one[rate],
                      "; wayside_monitor listen:=true (site_engine), the passes from the probe's process")
            for rate in rates]
    out += [_rate_row(f"one-process graph of four model nodes, {rate:g} passes/s arriving one at a time",
                      one_nodes[rate], "; wayside_monitor listen:=true models:=nodes (the layout of 0.24.0)")
            for rate in rates]
    out += [_rate_row(f"no-op one-process graph, {rate:g} passes/s arriving one at a time", bare_one[rate],
                      "; the no-op graph's stand-ins and the real recorder in one process, listening as "
                      "wayside_monitor listen:=true does", latency=False) for rate in rates]
    return out


def _rate_row(what: str, r: dict[str, Any], detail: str, latency: bool = True) -> tuple[str, str, str]:
    lat = (f"latency pass to last output p50 {r['p50_ms']:.0f} ms, p95 {r['p95_ms']:.0f} ms over {r['passes']} passes"
           + (f"; {r['lost']} incomplete" if r["lost"] else "")) if latency else f"over {r['passes']} passes"
    return (what, f"{100 * r['core']:.0f} % of a core", lat + detail)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--source", default="bags/sample")
    ap.add_argument("--rates", default="1,100", help="passes per second, comma-separated")
    ap.add_argument("--seconds", type=float, default=10.0, help="length of each rate's run [s]")
    ap.add_argument("--idle", type=float, default=10.0, help="length of the idle measurement [s]")
    ap.add_argument("--kept-days", type=float, help="days of a busy site's traffic the estimators' state holds "
                    "(default the site's corrugation.history_days; 0: an empty state)")
    ns = ap.parse_args()
    for row in rows(ns.site, ns.source, [float(r) for r in ns.rates.split(",")], ns.seconds, ns.idle, ns.kept_days):
        print(" | ".join(row))


if __name__ == "__main__":
    main()
