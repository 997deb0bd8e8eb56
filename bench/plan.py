"""The network grinding programme (rail-monitor plan's solver): sites x years solved without a
capacity, and with a capacity of 85 % of that programme's busiest month, and with three options per
site (grind, speed control, a friction modifier), in one run; and with
--simulated N, a network simulated whole (rail-monitor simulate --network: each curve's history and
surveys of a true rail), planned from its histories, its realised cost over the horizon on the true
rails against a fixed cycle and grinding at the median forecast, and how the forecasts' P10, P50 and
P90 fall against the true rails' due dates and cycles (calibrated: 10, 50 and 90 % of the truths
below them).

Run alone: ros2_ws/run python -m bench.plan [--sites 500] [--years 5] [--simulated 50 --days 90]
"""

from __future__ import annotations

import argparse
import csv
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import bench  # noqa: F401  (private DDS domain, one maths thread)
from rail_monitor.batch.sites import outlook_site, read_manifest
from rail_monitor.cli import main as cli
from rail_monitor.economics import baselines
from rail_monitor.economics.programme import Z90, Rules, offset_days, plan
from rail_monitor.simulation.network import network_outlooks

Row = tuple[str, str, str]


def rows(sites: int, years: int) -> list[Row]:
    outlooks = network_outlooks(sites, 2026)
    free = plan(outlooks, Rules(12 * years, 0))
    peak = int(np.bincount(np.concatenate(free.visits)).max())
    held = plan(outlooks, Rules(12 * years, 0, capacity=int(0.85 * peak)))
    busiest = int(np.bincount(np.concatenate(held.visits)).max())
    return [(f"programme, {sites} sites x {years} years, no capacity", f"{free.seconds:.1f} s",
             f"{free.schedules:,} candidate schedules; busiest month {peak} visits; {free.status.split('(')[0]}"),
            (f"programme, {sites} sites x {years} years, {int(0.85 * peak)} visits a month", f"{held.seconds:.1f} s",
             f"busiest month {busiest}; expected cost x{held.expected_cost.sum() / free.expected_cost.sum():.3f} "
             f"of the unlimited; largest risk {100 * held.risk.max():.1f} %; {held.status.split('(')[0]}"),
            options_row(sites, years)]


def options_row(sites: int, years: int) -> Row:
    """The same network with every site offering speed control and a friction modifier."""
    outlooks = network_outlooks(sites, 2026, options=True)
    prog = plan(outlooks, Rules(12 * years, 0))
    alone = plan([o.under("grind") for o in outlooks], Rules(12 * years, 0))
    taken = {name: prog.option.count(name) for name in ("grind", "speed_control", "friction_modifier")}
    return (f"programme, {sites} sites x {years} years, three options each", f"{prog.seconds:.1f} s",
            f"{prog.schedules:,} candidates; sites per option {taken}; expected cost x"
            f"{prog.expected_cost.sum() / alone.expected_cost.sum():.3f} of grinding alone; "
            f"{prog.status.split('(')[0]}")


def simulated_rows(curves: int, days: float, years: int) -> list[Row]:
    with tempfile.TemporaryDirectory() as tmp:
        net = Path(tmp) / "net"
        t = time.perf_counter()
        assert cli(["simulate", "--network", str(curves), "--days", str(days), "--out", str(net)]) == 0
        simulated = time.perf_counter() - t
        truth = {r["site_id"]: r for r in csv.DictReader((net / "truth.csv").open())}
        t = time.perf_counter()
        outlooks = [outlook_site(job) for job in read_manifest(net / "sites.yaml", checkpoints=True)]
        read = time.perf_counter() - t
    rules = Rules(12 * years, max(o.newest_ns for o in outlooks))
    every = baselines.median_cycle_months(outlooks, rules)
    # the risk limit's price: at 0.5 the programme only minimises expected cost
    runs = {"programme": plan(outlooks, rules).visits,
            "programme, risk limit 0.5": plan(outlooks, replace(rules, risk_limit=0.5)).visits,
            f"fixed {every}-month cycle": baselines.fixed_cycle(outlooks, rules, every),
            "at the median forecast": baselines.when_due(outlooks, rules)}
    # a curve past its threshold when the programme starts is late at its first visit whatever the plan
    overdue = sum(float(truth[o.site_id]["true_due_days"]) <= offset_days(o, rules) for o in outlooks)
    spread = np.median([np.log(o.cycle_days[2] / o.cycle_days[0]) / (2 * Z90) for o in outlooks])
    rows = [(f"simulated network, {curves} curves x {days:g} days", f"{simulated:.0f} s",
             f"simulated with monthly surveys; read into outlooks in {read:.0f} s; median ln-spread of the "
             f"cycle {spread:.2f}; {overdue} curves past their threshold at the start"),
            calibration_row(outlooks, truth)]
    for name, visits in runs.items():
        res = [baselines.realised(o, rules, v, float(truth[o.site_id]["true_due_days"]),
                                  [float(c) for c in truth[o.site_id]["true_cycle_days"].split()])
               for o, v in zip(outlooks, visits, strict=True)]
        n = sum(len(v) for v in visits)
        rows.append((f"  realised over {years} years on the true rails: {name}", f"{sum(r[0] for r in res):,.0f}",
                     f"{n} visits, {sum(r[1] for r in res)} thresholds passed first"))
    return rows


def calibration_row(outlooks: list, truth: dict[str, dict[str, str]]) -> Row:
    """The share of the true due dates and of the true cycles (each grind's) below each forecast
    quantile: 10, 50 and 90 % where the forecasts are calibrated."""
    due = np.array([[float(truth[o.site_id]["true_due_days"]) < d for d in o.due_days] for o in outlooks])
    cycles = np.concatenate([[[float(c) < d for d in o.cycle_days] for c in truth[o.site_id]["true_cycle_days"].split()]
                             for o in outlooks])
    return ("  truths below the forecasts' P10 / P50 / P90", f"{100 * cycles.mean(axis=0)[1]:.0f} %",
            "cycles {:.0f} / {:.0f} / {:.0f} %; due dates {:.0f} / {:.0f} / {:.0f} %".format(
                *(100 * cycles.mean(axis=0)), *(100 * due.mean(axis=0))))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sites", type=int, default=500)
    ap.add_argument("--years", type=int, default=5)
    ap.add_argument("--simulated", type=int, default=0, help="also a network of this many curves simulated whole")
    ap.add_argument("--days", type=float, default=90.0, help="history of each simulated curve [day]")
    ns = ap.parse_args()
    out = rows(ns.sites, ns.years) + (simulated_rows(ns.simulated, ns.days, ns.years) if ns.simulated else [])
    for what, figure, note in out:
        print(f"{what:55s} {figure:>10s}  {note}")


if __name__ == "__main__":
    main()
