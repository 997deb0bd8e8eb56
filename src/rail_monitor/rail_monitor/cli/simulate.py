"""rail-monitor simulate: a seeded pass history for a site, into a bag and/or a CSV file."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from rail_monitor.cli.common import add_site_option, fresh_output, site_values
from rail_monitor.core.errors import RailMonitorError

if TYPE_CHECKING:  # the command imports the models only when it runs
    from rail_monitor.core.passes import PassTable
    from rail_monitor.core.site import Site
    from rail_monitor.corrugation.surveys import MaintenanceEvent
    from rail_monitor.measured.records import Measurement


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("simulate", help="generate a seeded pass history for a site into a bag and/or CSV")
    add_site_option(s)
    s.add_argument("--out", help="bag folder to create (MCAP)")
    s.add_argument("--csv", help="CSV file to write")
    s.add_argument("--days", type=float, help="override simulator.days [day]")
    s.add_argument("--seed", type=int, help="override simulator.seed [-]")
    s.add_argument("--force", action="store_true", help="replace an existing bag folder that rail_monitor created")
    t = s.add_argument_group("a measured site: a true rail, its surveys and a noise station (into the bag)")
    t.add_argument("--k-b-factor", type=float, default=1.0, help="the true rail's K_b over the configured one [-]")
    t.add_argument("--surveys-every-days", type=float, default=None,
                   help="roughness surveys of the true rail, 1 dB per band, every so many days (default: none; "
                   "with --network, 30)")
    t.add_argument("--measured", action="store_true", help="a noise station measuring every pass of the true rail "
                   "(4 vehicles with wheel flats among the fleets; their ids are printed)")
    t.add_argument("--measured-csv", help="also write the station's measurements as its CSV")
    t.add_argument("--true-creep", action="append", default=[], metavar="STATE=K1,K2",
                   help="the true rail's creep curve of a friction state (dry, wet, friction_modifier, contaminated), "
                   "kept from the fitting: the station hears squeal by it (repeatable)")
    n = s.add_argument_group("a network of curves (for rail-monitor plan)")
    n.add_argument("--network", type=int, default=0, metavar="N",
                   help="write N curves varied from the site file into the folder --out: radius, traffic, wet "
                   "weather and a true K_b of their own, each with its site file and its history bag with the true "
                   "rail's surveys, a manifest (sites.yaml) and each true rail's K_b, due date and cycle (truth.csv)")
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.csv_io import write_csv
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.core.simulator_params import simulator_config
    from rail_monitor.core.site import site_from_values
    from rail_monitor.simulation.simulator import applicator_events, simulate

    values = site_values(ns.site)
    if ns.days is not None:
        values["simulator.days"] = ns.days
    if ns.seed is not None:
        values["simulator.seed"] = ns.seed
    if ns.network:
        return _network(ns, values)
    ns.surveys_every_days = ns.surveys_every_days or 0.0
    site = site_from_values(values)
    cfg = simulator_config(values)
    table = simulate(site, cfg)
    if not ns.out and not ns.csv:
        raise RailMonitorError("give --out BAG and/or --csv FILE")
    if ns.k_b_factor <= 0 or ns.surveys_every_days < 0:
        raise RailMonitorError("--k-b-factor must be positive and --surveys-every-days not negative")
    if ns.true_creep and not (ns.measured or ns.measured_csv or ns.surveys_every_days > 0):
        raise RailMonitorError("--true-creep is the true rail's: give --measured (or --surveys-every-days) too")
    events, measured = _measured_site(ns, values, site, table)
    if ns.out:
        fresh_output(Path(ns.out), ns.force)
        applicators = applicator_events(cfg)
        write_passes_bag(table, ns.out, site.site_id, events=events, measurements=measured, applicators=applicators)
        print(f"wrote {len(table)} passes, {len(events)} surveys, {len(measured)} measured pass-bys and "
              f"{len(applicators)} friction applicator events to bag {ns.out}")
    if ns.csv:
        write_csv(table, ns.csv)
        print(f"wrote {len(table)} passes to {ns.csv}")
    return 0


def _measured_site(ns: argparse.Namespace, values: dict, site: Site, table: PassTable
                   ) -> tuple[list[MaintenanceEvent], list[Measurement]]:
    """The true rail's surveys and the station's measurements the options ask for."""
    events, measured = [], []
    creep = parse_true_creep(ns.true_creep)
    if ns.surveys_every_days > 0:
        from rail_monitor.core.site import site_from_values
        from rail_monitor.simulation.measurements import true_values
        from rail_monitor.simulation.surveys import simulate_surveys

        truth = true_values(values, creep)
        series = simulate_surveys(site_from_values(truth) if creep else site, truth, table, ns.k_b_factor,
                                  ns.surveys_every_days, 1.0, int(values["simulator.seed"]) + 100)
        events = series.events()
        print(f"true rail: K_b x {ns.k_b_factor:g} = {', '.join(f'{k:.3g}' for k in series.true_k_b)} "
              "(dry, wet, modifier, contaminated)")
    if ns.measured or ns.measured_csv:
        from rail_monitor.simulation.measurements import station_on_true_rail

        station = station_on_true_rail(table, values, ns.k_b_factor, int(values["simulator.seed"]), creep)
        measured = station.measurements
        print(f"noise station: {len(measured)} measured pass-bys; vehicles with wheel flats: "
              f"{', '.join(sorted(station.defective))}")
        if ns.measured_csv:
            from rail_monitor.bagio.measured_csv import write_measured_csv

            write_measured_csv(measured, ns.measured_csv)
            print(f"wrote the station's measurements to {ns.measured_csv}")
    return events, measured


def parse_true_creep(items: list[str]) -> dict[str, tuple[float, float]]:
    """--true-creep STATE=K1,K2 options as {state: (k1, k2)} (RailMonitorError, one line, for a bad one)."""
    from rail_monitor.core.friction import FRICTION_BY_NAME

    out = {}
    for item in items:
        state, _, curve = item.partition("=")
        try:
            k1, k2 = (float(x) for x in curve.split(","))
        except ValueError:
            raise RailMonitorError(f"--true-creep {item!r}: give STATE=K1,K2, e.g. wet=0.18,-0.015") from None
        if state not in FRICTION_BY_NAME or not 0.0 < k1 < 2.0 or not -1.0 < k2 < 1.0:
            raise RailMonitorError(f"--true-creep {item!r}: the state is one of {', '.join(FRICTION_BY_NAME)}, "
                                   "0 < K1 < 2 and -1 < K2 < 1")
        out[state] = (k1, k2)
    return out


def _network(ns: argparse.Namespace, values: dict) -> int:
    """simulate --network: N curves from the site file (simulation.network), each simulated with its
    true rail's surveys, into one folder with a manifest and the truth."""
    import csv

    from rail_monitor.bagio.output_folder import claim_output_folder
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.cli.common import site_file
    from rail_monitor.cli.site import edited_site_text
    from rail_monitor.core.simulator_params import simulator_config
    from rail_monitor.core.site import site_from_values
    from rail_monitor.corrugation.config import corrugation_config
    from rail_monitor.simulation.network import network_sites, true_outlook_days
    from rail_monitor.simulation.simulator import applicator_events, simulate
    from rail_monitor.simulation.surveys import simulate_surveys
    from rail_monitor.site_file import load_parameter_file

    every = 30.0 if ns.surveys_every_days is None else ns.surveys_every_days
    if not ns.out or ns.csv or ns.measured or ns.measured_csv or ns.true_creep or ns.k_b_factor != 1.0:
        raise RailMonitorError("--network writes a folder: give --out DIR, and no --csv, --measured, --true-creep "
                               "or --k-b-factor (each curve draws its own)")
    if not 1 <= ns.network <= 10_000 or every < 0:
        raise RailMonitorError("--network must be 1-10000 curves and --surveys-every-days not negative")
    out = Path(ns.out)
    fresh_output(out, ns.force)
    claim_output_folder(out)
    base = site_file(ns.site).read_text()
    extra = [f"simulator.days={values['simulator.days']}"]
    rows = []
    ratio_sd = corrugation_config(values).kb_prior_ratio_sd
    for curve in network_sites(ns.network, int(values["simulator.seed"]), values["simulator.trains_per_hour"],
                               ratio_sd):
        text, _ = edited_site_text(base, [*curve.changes, *extra])
        (out / f"{curve.site_id}.yaml").write_text(text)
        v = load_parameter_file(out / f"{curve.site_id}.yaml")
        site, cfg = site_from_values(v), simulator_config(v)
        table = simulate(site, cfg)
        events = []
        if every > 0:
            series = simulate_surveys(site, v, table, curve.k_b_factors, every, 1.0, int(v["simulator.seed"]) + 100)
            events = series.events()
        write_passes_bag(table, out / curve.site_id, site.site_id, events=events, applicators=applicator_events(cfg))
        due, cycles = true_outlook_days(site, v, table, curve.k_b_factors, seed=int(v["simulator.seed"]) + 200)
        rows.append({"site_id": curve.site_id, "k_b_factor": curve.k_b_factor,
                     "k_b_by_friction": " ".join(f"{f:g}" for f in curve.k_b_factors),
                     "curve_radius_m": site.curve_radius_m,
                     "passes": len(table), "surveys": len(events), "true_due_days": due,
                     "true_cycle_days": " ".join(f"{c:.6g}" for c in cycles)})
    (out / "sites.yaml").write_text("sites:\n" + "".join(f"  - site: {r['site_id']}.yaml\n    history: {r['site_id']}\n"
                                                         for r in rows))
    with (out / "truth.csv").open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {len(rows)} curves ({sum(r['passes'] for r in rows)} passes, surveys every {every:g} days) to {out}: "
          f"sites.yaml for rail-monitor plan, truth.csv with each true rail's K_b factor, due date and cycles")
    return 0
