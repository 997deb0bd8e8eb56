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
    t.add_argument("--surveys-every-days", type=float, default=0.0,
                   help="roughness surveys of the true rail, 1 dB per band, every so many days (0: none)")
    t.add_argument("--measured", action="store_true", help="a noise station measuring every pass of the true rail "
                   "(4 vehicles with wheel flats among the fleets; their ids are printed)")
    t.add_argument("--measured-csv", help="also write the station's measurements as its CSV")
    t.add_argument("--true-creep", action="append", default=[], metavar="STATE=K1,K2",
                   help="the true rail's creep curve of a friction state (dry, wet, friction_modifier, contaminated), "
                   "kept from the fitting: the station hears squeal by it (repeatable)")
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
        from rail_monitor.corrugation.surveys import KIND_SURVEY, MaintenanceEvent
        from rail_monitor.simulation.measurements import true_values
        from rail_monitor.simulation.surveys import simulate_surveys

        truth = true_values(values, creep)
        series = simulate_surveys(site_from_values(truth) if creep else site, truth, table, ns.k_b_factor,
                                  ns.surveys_every_days, 1.0, int(values["simulator.seed"]) + 100)
        events = [MaintenanceEvent(int(t), KIND_SURVEY, series.wavelength_m, series.amplitude_m[k])
                  for k, t in enumerate(series.stamp_ns.tolist())]
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
