"""rail-monitor plan: a grinding programme for a network of sites (economics.programme) from their
histories or checkpoints, ranked, priced and set against grinding on a fixed cycle or when due."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.text import printable
from rail_monitor.core.timeutil import NS_PER_DAY, format_iso_ns, parse_iso_ns

WIDE = 4.0  # a cycle's P90/P10 above which the printout says a survey would pay (ln-spread over 0.54)


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("plan", help="a grinding programme for many sites: ranked by due date, visits by month "
                       "within a capacity and budget, expected cost against a fixed cycle and grinding when due")
    s.add_argument("manifest", help="YAML list of sites as for batch --manifest (site:, and history: or a "
                   "live site's checkpoint:); grinding costs come from each site file's economics.* parameters")
    s.add_argument("--years", type=float, default=5.0, help="horizon [years]")
    s.add_argument("--start", help="when the programme's first month begins, ISO 8601 (default: the newest pass "
                   "of any site)")
    s.add_argument("--capacity", type=int, default=0, help="most site visits in a month (default: no limit)")
    s.add_argument("--budget", type=float, default=0.0, help="most preventive grinding cost per programme year, in "
                   "the sites' cost unit (default: no limit)")
    s.add_argument("--risk", type=float, default=0.1, help="most chance a site's worst band passes its threshold "
                   "before its visit (0.1: visits before the forecast's P10 date)")
    s.add_argument("--fixed-cycle-months", type=int, default=0, help="the fixed cycle compared with (default: the "
                   "median of the sites' grinding cycles, P50)")
    s.add_argument("--csv", metavar="PATH", help="write the programme, one row per visit")
    s.add_argument("--xlsx", metavar="PATH", help="write the programme and the ranking as a workbook")
    s.add_argument("--plot", metavar="PNG", help="save the programme's timeline: each site's due date P10-P90 and "
                   "its visits (the 40 due first)")
    s.add_argument("--workers", type=int, default=0, help="worker processes reading the sites (default: one per "
                   "core)")
    s.add_argument("--scheduler", help="address of a running Dask scheduler instead of a local cluster")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.batch.sites import outlook_site, read_manifest, run_sites
    from rail_monitor.economics import baselines
    from rail_monitor.economics.programme import MONTH_DAYS, Rules, plan

    if not 0 < ns.years <= 50 or not 0 < ns.risk < 1 or ns.capacity < 0 or ns.budget < 0 or ns.fixed_cycle_months < 0:
        raise RailMonitorError("--years must be in (0, 50], --risk in (0, 1), and --capacity, --budget and "
                               "--fixed-cycle-months not negative")
    outlooks = run_sites(read_manifest(ns.manifest, checkpoints=True), ns.workers, ns.scheduler or "",
                         task=outlook_site)
    ids = [o.site_id for o in outlooks]
    if len(set(ids)) != len(ids):
        twice = ", ".join(sorted({i for i in ids if ids.count(i) > 1}))
        raise RailMonitorError(f"{ns.manifest}: site ids repeat ({twice}): each site needs its own site_id")
    start = parse_iso_ns(ns.start) if ns.start else max(o.newest_ns for o in outlooks)
    rules = Rules(max(1, round(12 * ns.years)), start, ns.capacity, ns.budget, ns.risk)
    prog = plan(outlooks, rules)
    every = ns.fixed_cycle_months or baselines.median_cycle_months(outlooks, rules)

    def month(m: int) -> str:
        return format_iso_ns(int(start + m * MONTH_DAYS * NS_PER_DAY))[:10]

    print(f"plan: {len(outlooks)} sites, {rules.months} months from {month(0)}; capacity "
          f"{ns.capacity or 'unlimited'} visits a month, budget {ns.budget or 'unlimited'} a year, risk limit "
          f"{100 * ns.risk:g} %")
    print(f"{'site':<20} {'due P10':>10} {'due P50':>10} {'due P90':>10} {'cycle P10-P50-P90 [d]':>22} "
          f"{'visit cost':>11} {'cost/year P10-P90':>19}")
    wide = []
    for o in sorted(outlooks, key=lambda o: o.newest_ns / NS_PER_DAY + o.due_days[1]):
        due = [_date(o.newest_ns, d) for d in o.due_days]
        lo, _, hi = o.cost_per_year()
        cycle = "-".join(f"{d:.0f}" if np.isfinite(d) else "never" for d in o.cycle_days)
        print(f"{printable(o.site_id)[:20]:<20} {due[0]:>10} {due[1]:>10} {due[2]:>10} {cycle:>22} "
              f"{o.visit_cost:>11.0f} {lo:>9.0f}-{hi:<9.0f}")
        if o.cycle_days[2] > WIDE * o.cycle_days[0]:
            wide.append(o.site_id)
    if wide:
        names = ", ".join(map(printable, wide))
        print(f"plan: {len(wide)} site(s) with a cycle's P90 over {WIDE:g} times its P10 ({names}): "
              "holding the risk limit there takes visits far more often than the median needs; a roughness survey "
              "narrows K_b's posterior, and so the forecast")
    print(f"plan: programme ({prog.status.split('(')[0].strip()}, {prog.seconds:.1f} s over {prog.schedules} "
          "candidate schedules):")
    for site, visits, cost, risk in zip(prog.sites, prog.visits, prog.expected_cost, prog.risk, strict=True):
        print(f"  {printable(site)[:20]:<20} {', '.join(month(int(m))[:7] for m in visits) or 'no visit':<40} "
              f"expected cost {cost:.0f}, largest risk {100 * risk:.1f} %")
    compared = {"programme": prog.visits, f"fixed {every}-month cycle": baselines.fixed_cycle(outlooks, rules, every),
                "when due (forecast median)": baselines.when_due(outlooks, rules)}
    for name, visits in compared.items():
        cost, _, lates = baselines.expected(outlooks, rules, visits)
        print(f"plan: {name}: {sum(len(v) for v in visits)} visits, expected cost {cost.sum():.0f}, "
              f"{lates.sum():.2f} thresholds expected to pass before a visit")
    if ns.csv or ns.xlsx:
        _write(ns, outlooks, prog, month)
    if ns.plot:
        from rail_monitor.report.programme_plot import programme_timeline

        programme_timeline(outlooks, prog, rules).savefig(ns.plot, dpi=110)
        print(f"plan: timeline saved to {printable(ns.plot)}")
    return 0


def _date(newest_ns: int, days: float) -> str:
    from rail_monitor.corrugation.forecast import MAX_DATED_DAYS

    return format_iso_ns(int(newest_ns + days * NS_PER_DAY))[:10] if days <= MAX_DATED_DAYS else "never"


def _write(ns: argparse.Namespace, outlooks: list, prog, month) -> None:
    import pandas as pd

    visits = pd.DataFrame([{"site_id": s, "visit": i + 1, "month_start": month(int(m)), "visit_cost": o.visit_cost}
                           for o, s, v in zip(outlooks, prog.sites, prog.visits, strict=True)
                           for i, m in enumerate(v)], columns=["site_id", "visit", "month_start", "visit_cost"])
    ranking = pd.DataFrame([{"site_id": o.site_id, **{f"due_{p}": _date(o.newest_ns, d)
                                                      for p, d in zip(("p10", "p50", "p90"), o.due_days, strict=True)},
                             **{f"cycle_{p}_days": d for p, d in zip(("p10", "p50", "p90"), o.cycle_days, strict=True)},
                             "visit_cost": o.visit_cost, "late_visit_cost": o.late_visit_cost,
                             "expected_cost": c, "largest_risk": r}
                            for o, c, r in zip(outlooks, prog.expected_cost, prog.risk, strict=True)])
    if ns.csv:
        visits.to_csv(ns.csv, index=False)
        print(f"plan: programme written to {printable(ns.csv)}")
    if ns.xlsx:
        with pd.ExcelWriter(Path(ns.xlsx), engine="openpyxl") as xl:
            visits.to_excel(xl, sheet_name="programme", index=False)
            ranking.to_excel(xl, sheet_name="sites", index=False)
        print(f"plan: programme and sites written to {printable(ns.xlsx)}")
