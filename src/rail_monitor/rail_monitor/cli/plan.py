"""rail-monitor plan: a grinding programme for a network of sites (economics.programme) from their
histories or checkpoints, ranked, priced and set against grinding on a fixed cycle or when due."""

from __future__ import annotations

import argparse
from pathlib import Path

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.text import printable
from rail_monitor.core.timeutil import iso_day, parse_iso_ns


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
    s.add_argument("--report", metavar="DIR", help="write a report for a manager into DIR: what to grind when, what "
                   "it costs and saves against a fixed cycle and grinding when due, and the risk left (index.html "
                   "and programme.pdf, with the timeline)")
    s.add_argument("--replan", metavar="CSV", help="re-plan as the histories went: the programme solved again on "
                   "each site's outlook made at each survey, grinding or indirect observation, in stamp order, as "
                   "grinding_planner does live; one row per re-plan (histories only, not checkpoints)")
    s.add_argument("--time-limit", type=float, default=60.0, help="longest a solve may take [s]; at the limit the "
                   "best programme found is taken, its status saying so (a capacity that binds makes it hard)")
    s.add_argument("--workers", type=int, default=0, help="worker processes reading the sites (default: one per "
                   "core)")
    s.add_argument("--scheduler", help="address of a running Dask scheduler instead of a local cluster")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.batch.sites import outlook_history, outlook_site, read_manifest, run_sites
    from rail_monitor.economics import baselines
    from rail_monitor.economics.outlook import WIDE
    from rail_monitor.economics.programme import Rules, plan
    from rail_monitor.report.programme_page import days_text

    if (not 0 < ns.years <= 50 or not 0 < ns.risk < 1 or ns.capacity < 0 or ns.budget < 0 or ns.fixed_cycle_months < 0
            or not ns.time_limit > 0):
        raise RailMonitorError("--years must be in (0, 50], --risk in (0, 1), --time-limit above 0, and --capacity, "
                               "--budget and --fixed-cycle-months not negative")
    results = run_sites(read_manifest(ns.manifest, checkpoints=True), ns.workers, ns.scheduler or "",
                        task=outlook_history if ns.replan else outlook_site)
    outlooks = [r[0] for r in results] if ns.replan else results
    ids = [o.site_id for o in outlooks]
    if len(set(ids)) != len(ids):
        twice = ", ".join(sorted({i for i in ids if ids.count(i) > 1}))
        raise RailMonitorError(f"{ns.manifest}: site ids repeat ({twice}): each site needs its own site_id")
    start = parse_iso_ns(ns.start) if ns.start else max(o.newest_ns for o in outlooks)
    rules = Rules.over(ns.years, start, ns.capacity, ns.budget, ns.risk)
    prog = plan(outlooks, rules, ns.time_limit)
    every = ns.fixed_cycle_months or baselines.median_cycle_months(outlooks, rules)

    def month(m: int) -> str:
        return iso_day(rules.month_ns(m))

    print(f"plan: {len(outlooks)} sites, {rules.months} months from {month(0)}; capacity "
          f"{ns.capacity or 'unlimited'} visits a month, budget {ns.budget or 'unlimited'} a year, risk limit "
          f"{100 * ns.risk:g} %")
    print(f"{'site':<20} {'due P10':>10} {'due P50':>10} {'due P90':>10} {'cycle P10-P50-P90 [d]':>22} "
          f"{'visit cost':>11} {'cost/year P10-P90':>19}")
    wide = []
    for o in sorted(outlooks, key=lambda o: o.due_day):
        due = [iso_day(d) for d in o.due_ns()]
        lo, _, hi = o.cost_per_year()
        cycle = days_text(o.cycle_days)
        print(f"{printable(o.site_id)[:20]:<20} {due[0]:>10} {due[1]:>10} {due[2]:>10} {cycle:>22} "
              f"{o.visit_cost:>11.0f} {lo:>9.0f}-{hi:<9.0f}")
        for option in o.options if any(c.name != "grind" for c in o.options) else ():
            print(f"    option {option.name}: cycle {days_text(option.cycle_days)} d, running cost "
                  f"{option.cost_per_year:.0f} a year" + (f"; {option.effects}" if option.effects else ""))
        if o.wide:
            wide.append(o.site_id)
    if wide:
        names = ", ".join(map(printable, wide))
        print(f"plan: {len(wide)} site(s) with a cycle's P90 over {WIDE:g} times its P10 ({names}): "
              "holding the risk limit there takes visits far more often than the median needs; a roughness survey "
              "narrows K_b's posterior, and so the forecast")
    print(f"plan: programme ({prog.status.split('(')[0].strip()}, {prog.seconds:.1f} s over {prog.schedules} "
          "candidate schedules):")
    for site, visits, option, cost, risk in zip(prog.sites, prog.visits, prog.option, prog.expected_cost, prog.risk,
                                                strict=True):
        run = "" if option == "grind" or not len(visits) else f" ({option} from the first visit)"
        print(f"  {printable(site)[:20]:<20} {', '.join(month(int(m))[:7] for m in visits) or 'no visit':<40} "
              f"expected cost {cost:.0f}, largest risk {100 * risk:.1f} %{run}")
    runs = baselines.priced(outlooks, rules, prog, every)
    for r in runs:
        print(f"plan: {r.name}: {r.count} visits, expected cost {r.cost:.0f}, {r.lates:.2f} thresholds expected "
              "to pass before a visit")
    if ns.csv or ns.xlsx:
        _write(ns, outlooks, prog, month)
    if ns.plot:
        from rail_monitor.report.programme_plot import programme_timeline

        programme_timeline(outlooks, prog, rules).savefig(ns.plot, dpi=110)
        print(f"plan: timeline saved to {printable(ns.plot)}")
    if ns.report:
        from rail_monitor.report.programme_page import write_programme_report

        files = write_programme_report(Path(ns.report), outlooks, prog, rules, runs, wide)
        print(f"plan: report for a manager written to {printable(files[-1])} and {printable(files[-2])}")
    if ns.replan:
        _replan(ns, [made for _, made in results])
    return 0


def _replan(ns: argparse.Namespace, histories: list) -> None:
    import pandas as pd

    from rail_monitor.economics.replan import Replanner, replay

    planner = Replanner(ns.years, ns.capacity, ns.budget, ns.risk, time_limit_s=ns.time_limit)
    rows = []
    for r in replay([x for made in histories for x in made], planner):
        p, rules = r.programme, r.rules
        firsts = [(int(v[0]), s) for s, v in zip(p.sites, p.visits, strict=True) if len(v)]
        m, site = min(firsts) if firsts else (-1, "")
        rows.append({"made": iso_day(r.stamp_ns), "site_id": r.site_id, "sites_planned": len(p.sites),
                     "start": iso_day(rules.start_ns), "visits": sum(len(v) for v in p.visits),
                     "expected_cost": float(p.expected_cost.sum()), "expected_late": float(p.lates.sum()),
                     "next_visit_site": site, "next_visit_month": iso_day(rules.month_ns(m))[:7] if m >= 0 else "",
                     "status": p.status})
    pd.DataFrame(rows, columns=["made", "site_id", "sites_planned", "start", "visits", "expected_cost",
                                "expected_late", "next_visit_site", "next_visit_month", "status"]).to_csv(
        ns.replan, index=False)
    print(f"plan: {len(rows)} re-plans, one per site outlook made in the histories, written to "
          f"{printable(ns.replan)}")


def _write(ns: argparse.Namespace, outlooks: list, prog, month) -> None:
    import pandas as pd

    columns = ["site_id", "visit", "month_start", "visit_cost", "option"]
    visits = pd.DataFrame([(s, i + 1, month(int(m)), o.visit_cost, c)
                           for o, s, v, c in zip(outlooks, prog.sites, prog.visits, prog.option, strict=True)
                           for i, m in enumerate(v)], columns=columns)
    ranking = pd.DataFrame([{"site_id": o.site_id, **{f"due_{p}": iso_day(d)
                                                      for p, d in zip(("p10", "p50", "p90"), o.due_ns(), strict=True)},
                             **{f"cycle_{p}_days": d for p, d in zip(("p10", "p50", "p90"), o.cycle_days, strict=True)},
                             "visit_cost": o.visit_cost, "late_visit_cost": o.late_visit_cost,
                             "option": opt, "expected_cost": c, "largest_risk": r}
                            for o, opt, c, r in zip(outlooks, prog.option, prog.expected_cost, prog.risk, strict=True)])
    if ns.csv:
        visits.to_csv(ns.csv, index=False)
        print(f"plan: programme written to {printable(ns.csv)}")
    if ns.xlsx:
        with pd.ExcelWriter(Path(ns.xlsx), engine="openpyxl") as xl:
            visits.to_excel(xl, sheet_name="programme", index=False)
            ranking.to_excel(xl, sheet_name="sites", index=False)
        print(f"plan: programme and sites written to {printable(ns.xlsx)}")
