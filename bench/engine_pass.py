"""Where a live pass's time goes: the site engine (rail_monitor.engine.site) fed one pass at a time,
as site_engine feeds it, on a busy site's corrugation state, on one thread and the numpy kernels
(as the node runs it). No DDS: the engine alone, which is what the node adds above rclpy's floor.

Each stage is timed by wrapping the function the engine calls for it (a wrapper costs about a
microsecond); the rest of the engine's own Python is "the engine's own bookkeeping".
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import bench  # noqa: F401  (private DDS domain, one maths thread)

STAGES = {  # stage: (object the engine calls it on, attribute)
    "rolling noise (every source model, on the state that includes the pass)": ("site", "noise_on_states"),
    "corrugation state and forecast": ("corrugation", "advance"),
    "squeal (contact, limit cycle, levels)": ("site", "predict_squeal"),
    "alert windows": ("site", "_feed_alerts"),
    "pass checks (validity, ahead of the stream, class defaults)": ("site", "rejection_reasons"),
    "measured pass-bys paired, residuals": ("engine", "_measured"),
    "settle (the alerts released between passes)": ("engine", "settle"),
}
DEFAULTS = ("site", "with_class_defaults")  # counted with the pass checks


def _timed(fn: Callable[..., Any], spent: dict[str, float], stage: str) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        t = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            spent[stage] += time.perf_counter() - t

    return wrapper


def split(site: str, source: str, kept_days: float, passes: int = 300, warm: int = 50) -> dict[str, Any]:
    """Mean wall time per pass [s] of feed + settle, alone and split by stage."""
    import rail_monitor.engine.site as site_module
    from bench.live import busy_checkpoint
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.engine.site import SiteEngine
    from rail_monitor.site_file import load_parameter_file

    values = load_parameter_file(site)
    table = read_passes(source).sorted().take(slice(0, passes + warm))
    n = len(table)
    with tempfile.TemporaryDirectory() as tmp:
        state = Path(tmp) / "busy.npz"
        kept = busy_checkpoint(site, kept_days, state) if kept_days > 0 else 0

        def engine() -> SiteEngine:
            e = SiteEngine(values, threads=1, engine="numpy")
            e.measured_live = True
            if kept:
                e.resume(str(state))
            return e

        def run(e: SiteEngine, warmed: Callable[[], None] = lambda: None) -> float:
            start = e.estimator.newest_ns + 60 * 10**9
            p = dataclasses.replace(table, stamp_ns=start + np.arange(n, dtype=np.int64) * 10**7,
                                    train_id=np.array([f"b{i}" for i in range(n)], object))
            clock = int(p.stamp_ns[-1]) + 10**9
            t = 0.0
            for i in range(n):
                if i == warm:
                    warmed()
                t0 = time.perf_counter()
                e.feed(p.take(slice(i, i + 1)), late=True, clock_ns=clock)
                e.settle()
                if i >= warm:
                    t += time.perf_counter() - t0
            return t / (n - warm)

        plain = run(engine())
        spent: dict[str, float] = defaultdict(float)
        e = engine()
        originals = []
        for stage, (where, name) in (*STAGES.items(), ("pass checks (validity, ahead of the stream, class "
                                                        "defaults)", DEFAULTS)):
            owner = {"site": site_module, "corrugation": e.corrugation, "engine": e}[where]
            originals.append((owner, name, getattr(owner, name)))
            setattr(owner, name, _timed(getattr(owner, name), spent, stage))
        try:
            wrapped = run(e, spent.clear)
        finally:
            for owner, name, fn in originals:
                setattr(owner, name, fn)
    per = {k: v / (n - warm) for k, v in spent.items()}
    return {"per_pass_s": plain, "wrapped_s": wrapped, "stages": per, "kept": kept, "passes": n - warm}


def replay(site: str, source: str, chunk: int, kernels: str) -> dict[str, float]:
    """The site engine alone over a history (no DDS, one thread), fed in chunks of ``chunk`` passes
    with each chunk's per-pass outputs encoded as the graph publishes them: wall time [s] of the
    engine (feed + settle) and of the outputs' CDR, on a second run (numba's kernels loaded)."""
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.engine.site import SiteEngine
    from rail_monitor.messages import outputs
    from rail_monitor.site_file import load_parameter_file

    values = load_parameter_file(site)
    table = read_passes(source).sorted()
    clock = int(table.stamp_ns[-1]) + 10**9
    spent = {"engine_s": 0.0, "outputs_s": 0.0}
    for _ in range(2):
        spent = dict.fromkeys(spent, 0.0)
        e = SiteEngine(values, threads=1, engine=kernels)
        e.measured_live = True  # as site_engine: a measurement may follow its pass
        for lo in range(0, len(table), chunk):
            t0 = time.perf_counter()
            result = e.feed(table.take(slice(lo, lo + chunk)), late=True, clock_ns=clock)
            t1 = time.perf_counter()
            outputs.per_pass(result, e.site.site_id)
            t2 = time.perf_counter()
            e.settle()
            spent["engine_s"] += t1 - t0 + time.perf_counter() - t2
            spent["outputs_s"] += t2 - t1
    return spent


def rows(site: str, source: str, kept_days: float, passes: int = 300) -> list[tuple[str, str, str]]:
    s = split(site, source, kept_days, passes)
    out = [("site engine, one pass fed alone (feed + settle)", f"{s['per_pass_s'] * 1e3:.2f} ms",
            f"mean over {s['passes']} passes on a state of {s['kept']:,} kept passes; one thread, numpy kernels, "
            f"no DDS: at 100 passes/s {100 * s['per_pass_s'] * 100:.0f} % of a core above rclpy's floor")]
    total = s["wrapped_s"]
    for stage, t in sorted(s["stages"].items(), key=lambda kv: -kv[1]):
        out.append((f"  of which {stage}", f"{t * 1e3:.2f} ms", f"{100 * t / total:.0f} %"))
    rest = total - sum(s["stages"].values())
    out.append(("  of which the engine's own bookkeeping", f"{rest * 1e3:.2f} ms", f"{100 * rest / total:.0f} %"))
    return out


if __name__ == "__main__":
    for row in rows("src/rail_monitor/config/curve_250.yaml", "bags/sample", 28.0):
        print(" | ".join(row))
