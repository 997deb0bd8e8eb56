"""Corrugation benchmark: growth tables, per-pass state update, batch throughput, what-if, advice.

Run: ros2_ws/run python -m bench.corrugation [--passes N]
Prints figures measured in this run only (compare ratios, not absolute times, across machines).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from bench.timing import best_of, header, parser
from rail_monitor.advice import growth as advice
from rail_monitor.advice import plan
from rail_monitor.advice.consequences import Consequences
from rail_monitor.core.passes import PassTable, with_class_defaults
from rail_monitor.core.site import site_from_values
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.growth import GrowthTables, _rail_receptance
from rail_monitor.engine import checkpoint
from rail_monitor.site_file import load_parameter_file


def passes(site, n: int, seed: int = 1, start: int = 0) -> PassTable:
    rng = np.random.default_rng(seed)
    classes = np.array(list(site.vehicles), dtype=object)
    return with_class_defaults(PassTable(
        stamp_ns=1_790_000_000 * 10**9 + np.arange(start, start + n) * 900 * 10**9,
        train_id=[f"T{i}" for i in range(start, start + n)],
        vehicle_class=classes[rng.integers(0, len(classes), n)], vehicle_count=rng.integers(3, 7, n),
        axle_count=[0] * n, speed_mps=rng.normal(18.0, 2.0, n).clip(8, 22), angle_of_attack_rad=[0.0] * n,
        wheel_load_n=[0.0] * n, friction_state=rng.integers(1, 5, n), train_length_m=[0.0] * n), site)


def costs(site_file: str, n: int = 20_000) -> dict[str, float]:
    """Per-pass cost [s] of the state update with its forecast (what corrugation_estimator
    publishes per pass): one pass at a time, and a history of n at once (advance_history)."""
    values = load_parameter_file(site_file)
    site, cfg = site_from_values(values), corrugation_config(values)
    tables = GrowthTables(site, cfg)
    est = CorrugationEstimator(site, cfg, tables)
    est.advance(passes(site, 3000, seed=2))
    rows = passes(site, 500, seed=3, start=3000)
    t = time.perf_counter()
    for i in range(len(rows)):
        est.advance(rows.take(slice(i, i + 1)))
        est.forecast()
    single = (time.perf_counter() - t) / len(rows)
    big = passes(site, n, seed=4)
    batch = best_of(lambda: CorrugationEstimator(site, cfg, tables).advance_history(big), 2) / n
    return {"pass_single": single, "pass_batch": batch}


def main() -> None:
    ap = parser(__doc__)
    ap.add_argument("--passes", type=int, default=200_000, help="passes of the batch run")
    ns = ap.parse_args()
    values = load_parameter_file(ns.site)
    site, cfg = site_from_values(values), corrugation_config(values)
    header("corrugation")

    t = time.perf_counter()
    _rail_receptance(site.track)
    t_rec = time.perf_counter() - t
    t = time.perf_counter()
    tables = GrowthTables(site, cfg)
    t_tab = time.perf_counter() - t
    print(f"rail receptance, 700 frequencies x 8 bay positions, 121 supports: {t_rec:8.2f} s (once per track)")
    print(f"growth tables, {len(tables.classes)} classes x {len(tables.speeds)} speeds x "
          f"{tables.filtered_kernel.shape[1]} bands x {tables.filtered_kernel.shape[3]} components: {t_tab:8.2f} s")

    warm = passes(site, 3000, seed=2)
    one = passes(site, 2000, seed=3, start=3000)  # after the warm-up: each one counts and prunes one
    est = CorrugationEstimator(site, cfg, tables)
    est.advance(warm)
    rows = [one.take(slice(i, i + 1)) for i in range(len(one))]
    t = time.perf_counter()
    for r in rows:
        est.advance(r)
    per_pass = (time.perf_counter() - t) / len(rows)
    t_fc = best_of(est.forecast, 20)
    print(f"state update, one pass (the node's call):   {per_pass * 1e6:10.0f} us")
    print(f"forecast ({len(est.kept)} kept passes):           {t_fc * 1e6:10.0f} us")

    big = passes(site, ns.passes, seed=4)

    def batch() -> None:
        CorrugationEstimator(site, cfg, tables).advance(big)

    t_b = best_of(batch, 3)
    print(f"batch, {ns.passes:,} passes:                {ns.passes / t_b:10.3g} passes/s "
          f"({t_b:.2f} s; one by one would be {per_pass / (t_b / ns.passes):.0f} x slower)")

    v = np.linspace(10, 22, 25)
    p = np.exp(-0.5 * ((v - 17) / 2) ** 2)
    t_ev = best_of(lambda: advice.evaluate(est, v, p), 20)
    cons = Consequences.of_values(site, values)
    t_adv = best_of(lambda: plan.advise(est, cons), 3)
    print(f"what-if evaluation, 25 speed bins:          {t_ev * 1e3:10.2f} ms")
    print(f"speed advice per class (noise, squeal, LP): {t_adv * 1e3:10.2f} ms")
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "state.npz"
        t_s = best_of(lambda: checkpoint.save(est, path), 5)
        t_l = best_of(lambda: checkpoint.load(CorrugationEstimator(site, cfg, tables), path), 5)
        print(f"checkpoint write (fsync) / read:            {t_s * 1e3:10.2f} / {t_l * 1e3:.2f} ms "
              f"({path.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
