"""Graph throughput against the rclpy ceiling, and the graph's peak memory against passes.

Each graph runs in its own process (``python -m bench.graph --one real|bare``): the real
wayside_monitor graph, or the no-op graph of bench.bare_graph with the same topology, message
types and sizes, QoS, executor and pass source, on the same input. Passes per second are over
the replay (first pass published to the last output recorded); set-up is reported apart. Then the
site engine alone (bench.engine_pass.replay), as the graph feeds it and at its fastest: the no-op
replay's time plus the engine's own is the best ratio a graph of one process could reach.
"""

from __future__ import annotations

import argparse
import json
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from bench.engine_pass import replay as engine_replay
from bench.timing import peak_rss_mb
from rail_monitor.site_file import load_parameter_file


def run_one(kind: str, source: str, site: str, output: str, executor: str = "single_threaded",
            max_batch: int = 200) -> dict[str, Any]:
    """Run one graph in this process; its figures."""
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.nodes.wayside_monitor import run_graph

    args = ["bench", "--ros-args", "--params-file", site, "-p", f"source:={source}", "-p", f"output:={output}",
            "-p", "progress:=false", "-p", f"executor:={executor}", "-p", f"max_batch:={max_batch}",
            "-p", "use_sim_time:=true",  # on pass time, as rail-monitor demo runs it (a history may end after today)
            "--log-level", "warn"]
    kw: dict[str, Any] = {}
    if kind == "bare":
        from bench.bare_graph import bare_graph

        models, recorder = bare_graph(read_passes(source), load_parameter_file(site), max_batch)
        kw = {"make_models": models, "make_recorder": recorder}
    r = run_graph(args, **kw)
    return {"kind": kind, "max_batch": max_batch, "passes": r.published, "replay_s": r.replay_s,
            "setup_s": r.wall_s - r.replay_s, "recorded": sum(r.recorded.values()), "peak_rss_mb": peak_rss_mb()}


def in_process(kind: str, source: str, site: str, executor: str = "single_threaded",
               max_batch: int = 200, output: str = "") -> dict[str, Any]:
    """run_one in a child process (a fresh rclpy context and a clean peak-memory figure);
    output: keep the bag there (default: a temporary folder)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-m", "bench.graph", "--one", kind, "--source", source, "--site", site,
               "--output", output or str(Path(tmp) / "bag"), "--executor", executor, "--max-batch", str(max_batch)]
        done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{kind} graph failed ({done.returncode}): {done.stderr.strip()[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def alternating(source: str, site: str, repeat: int, executor: str = "single_threaded", max_batch: int = 200,
                output: str = "") -> list[tuple[dict[str, Any], dict[str, Any]]]:
    """The no-op and the real graph in turn, ``repeat`` times (a shared machine's load drifts by
    20-30 % between runs, alike for both of a pair): (no-op, real) figures per pair; output: keep
    the last real run's bag there."""
    return [(in_process("bare", source, site, executor, max_batch),
             in_process("real", source, site, executor, max_batch, output if k == repeat - 1 else ""))
            for k in range(repeat)]


def ceiling_ratios(pairs: list[tuple[dict[str, Any], dict[str, Any]]]) -> list[float]:
    """Real / no-op passes per second of each pair (the no-op replay's time over the real's)."""
    return [bare["replay_s"] / real["replay_s"] for bare, real in pairs]


def engine_bounds(source: str, site: str, bare_runs: list[dict[str, Any]], max_batch: int = 200
                  ) -> list[tuple[str, dict[str, float], float]]:
    """The site engine alone over the history (bench.engine_pass.replay), as the graph feeds it and
    at its fastest: (what, its times, floor / (floor + its time)), floor the median replay time of
    the no-op runs. The last is the ratio to the ceiling of a one-process graph that added nothing
    else: in one process on one thread the engine's time adds to rclpy's."""
    floor_s = float(np.median([r["replay_s"] for r in bare_runs]))
    out = []
    for what, chunk, kernels in ((f"as the graph feeds it (backlogs of {max_batch}, numpy kernels)", max_batch,
                                  "numpy"),
                                 ("at its fastest (the whole history one chunk, compiled kernels)", 10**9, "numba")):
        t = engine_replay(site, source, chunk, kernels)
        out.append((what, t, floor_s / (floor_s + t["engine_s"] + t["outputs_s"])))
    return out


def recorder_process(source: str) -> dict[str, Any]:
    """mcap_recorder in its own process recording pass_replayer (another process) over DDS as fast
    as it acknowledges: messages recorded, replay wall time [s], the recorder's peak RSS [MB]."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "rec"
        rec = subprocess.Popen(["mcap_recorder", "--ros-args", "-p", f"output:={out}", "-p", "topics:=['/train_pass']",
                                "--log-level", "warn"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        t = time.monotonic()
        subprocess.run(["pass_replayer", "--ros-args", "-p", f"source:={source}", "-p", "wait_for_subscribers:=1",
                        "-p", "progress:=false", "-p", "publish_clock:=false", "--log-level", "warn"],
                       check=True, capture_output=True)
        replay_s = time.monotonic() - t
        peak = peak_rss_mb(rec.pid)  # the recording done (draining and closing add nothing)
        rec.send_signal(signal.SIGINT)
        if rec.wait(timeout=60) != 0:
            raise RuntimeError(f"mcap_recorder failed ({rec.returncode}): {rec.stderr.read()[-2000:]}")
        from rail_monitor.bagio.reader import read_passes

        recorded = len(read_passes(str(out)))
    return {"recorded": recorded, "replay_s": replay_s, "peak_rss_mb": peak}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--one", choices=("real", "bare"), help="run one graph in this process and print JSON")
    ap.add_argument("--source", default="bags/sample")
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--output", default="")
    ap.add_argument("--executor", default="single_threaded")
    ap.add_argument("--max-batch", type=int, default=200, help="queued passes a model callback takes at once")
    ap.add_argument("--repeat", type=int, default=3, help="no-op and real graphs run in turn this many times")
    ns = ap.parse_args()
    if ns.one:
        with tempfile.TemporaryDirectory() as tmp:
            print(json.dumps(run_one(ns.one, ns.source, ns.site, ns.output or str(Path(tmp) / "bag"),
                                     ns.executor, ns.max_batch)))
        return
    bare = in_process("bare", ns.source, ns.site, ns.executor, 1)
    pairs = alternating(ns.source, ns.site, ns.repeat, ns.executor, ns.max_batch)
    for r in (bare, *(r for pair in pairs for r in pair)):
        print(f"{r['kind']:>4} (max_batch {r['max_batch']}): {r['passes']} passes in {r['replay_s']:.1f} s = "
              f"{r['passes'] / r['replay_s']:.0f} passes/s (set-up {r['setup_s']:.1f} s, {r['recorded']} recorded, "
              f"peak RSS {r['peak_rss_mb']:.0f} MB)")
    ratios = ceiling_ratios(pairs)
    print(f"real / bare: {bare['replay_s'] / float(np.median([real['replay_s'] for _, real in pairs])):.2f}; "
          f"real / bare with the same batching: median {np.median(ratios):.2f} of "
          + ", ".join(f"{x:.2f}" for x in ratios))
    for what, t, bound in engine_bounds(ns.source, ns.site, [b for b, _ in pairs], ns.max_batch):
        print(f"the site engine alone {what}: {t['engine_s']:.2f} s, its outputs' CDR {t['outputs_s']:.2f} s; "
              f"no-op replay + that = {bound:.2f} of the ceiling")


if __name__ == "__main__":
    main()
