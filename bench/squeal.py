"""Squeal benchmark: closed form against time integration, vectorised throughput.

Run: ros2_ws/run python -m bench.squeal [--ode-cases N]
Prints figures measured in this run only (compare ratios, not absolute times, across machines).
"""

from __future__ import annotations

import time

import numpy as np

from bench.timing import best_of, header, parser
from rail_monitor.core.passes import PassTable, with_class_defaults
from rail_monitor.core.site import site_from_values
from rail_monitor.models import squeal, squeal_ode
from rail_monitor.site_file import load_parameter_file
from rail_monitor.squeal.config import squeal_config
from rail_monitor.squeal.predict import predict
from rail_monitor.whatif.squeal import rig_case


def costs(site_file: str, ode_cases: int = 3) -> dict[str, float]:
    """Per-case and per-pass costs [s]: closed form, time integration, the site prediction."""
    case = rig_case()
    args = (case.speed_mps, case.load_n, case.damping_nspm, case.k1, case.k2, case.k3_n)
    one = best_of(lambda: squeal.limit_cycle_amplitude(args[0], 0.39, *args[1:]), 50)
    t = []
    for vc in np.linspace(0.2, 0.5, ode_cases):
        t0 = time.perf_counter()
        squeal_ode.simulate_limit_cycle(case.speed_mps, float(vc), case.load_n, case.mass_kg, case.damping_nspm,
                                    case.stiffness_npm, case.k1, case.k2, case.k3_n)
        t.append(time.perf_counter() - t0)
    values = load_parameter_file(site_file)
    site, cfg = site_from_values(values), squeal_config(values)
    table = _passes(site, 10**5)
    batch = best_of(lambda: predict(cfg, site, table), 3) / len(table)
    single = best_of(lambda: predict(cfg, site, table.take(slice(0, 1))), 50)
    return {"closed_form": one, "ode": float(np.median(t)), "pass_single": single, "pass_batch": batch}


def _passes(site, n: int) -> PassTable:
    rng = np.random.default_rng(2)
    return with_class_defaults(PassTable(
        stamp_ns=np.arange(1, n + 1), train_id=["T"] * n, vehicle_class=["emu"] * n, vehicle_count=[4] * n,
        axle_count=[0] * n, speed_mps=rng.uniform(12, 22, n), angle_of_attack_rad=rng.uniform(0, 0.02, n),
        wheel_load_n=rng.uniform(55e3, 75e3, n), friction_state=rng.integers(1, 5, n), train_length_m=[0.0] * n),
        site)


def main() -> None:
    ap = parser(__doc__)
    ap.add_argument("--ode-cases", type=int, default=5, help="crabbing velocities integrated in time")
    ns = ap.parse_args()
    case = rig_case()
    args = (case.speed_mps, case.load_n, case.damping_nspm, case.k1, case.k2, case.k3_n)
    vcs = np.linspace(0.2, 0.5, ns.ode_cases)

    header("squeal")
    one = best_of(lambda: squeal.limit_cycle_amplitude(args[0], 0.39, *args[1:]), 50)
    ode_times, errs = [], []
    for vc in vcs:
        t = time.perf_counter()
        r = squeal_ode.simulate_limit_cycle(case.speed_mps, float(vc), case.load_n, case.mass_kg, case.damping_nspm,
                                        case.stiffness_npm, case.k1, case.k2, case.k3_n)
        ode_times.append(time.perf_counter() - t)
        cf = float(squeal.limit_cycle_amplitude(args[0], vc, *args[1:]).amplitude)
        errs.append(abs(r.amplitude / cf - 1))
    ode = float(np.median(ode_times))
    print(f"closed form, one case:          {one * 1e6:10.1f} us")
    print(f"time integration, one case:     {ode * 1e3:10.1f} ms  (median of {len(vcs)}, DOP853 to a settled cycle)")
    print(f"ratio ODE / closed form:        {ode / one:10.0f} x")
    print(f"largest |ODE / closed - 1|:     {max(errs):10.2e}")
    for n in (10**4, 10**5, 10**6):
        vc = np.random.default_rng(1).uniform(0.0, 0.6, n)
        t = best_of(lambda vc=vc: squeal.limit_cycle_amplitude(args[0], vc, *args[1:]), 3)
        print(f"closed form, {n:>9,} cases:    {n / t:10.3g} cases/s")

    values = load_parameter_file(ns.site)
    site, cfg = site_from_values(values), squeal_config(values)
    n = 10**5
    table = _passes(site, n)
    t = best_of(lambda: predict(cfg, site, table), 3)
    print(f"site prediction (contact, k3, limit cycle, levels, friction-modifier what-if), {n:,} passes: "
          f"{n / t:.3g} passes/s")
    one_pass = table.take(slice(0, 1))
    t1 = best_of(lambda: predict(cfg, site, one_pass), 50)
    print(f"site prediction, one pass (the node's call):  {t1 * 1e6:.0f} us")


if __name__ == "__main__":
    main()
