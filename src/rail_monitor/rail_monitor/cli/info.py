"""rail-monitor info: what a bag or CSV export holds (topics, counts, time span, pass statistics)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from rail_monitor.cli.common import SALVAGE_HELP


def add_parser(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("info", help="summarise a bag or CSV: topics, counts, time span, pass statistics")
    s.add_argument("bag", help="bag folder, .mcap, .db3 or .csv")
    s.add_argument("--topic", help="TrainPass topic to summarise (default: the only one)")
    s.add_argument("--salvage", action="store_true", help=SALVAGE_HELP)
    s.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.reader import bag_info, is_csv, read_passes, read_passes_reported
    from rail_monitor.bagio.site_record import describe, read_site_record
    from rail_monitor.codec.typestore import TRAIN_PASS
    from rail_monitor.core.text import printable
    from rail_monitor.core.timeutil import NS_PER_DAY, NS_PER_S, format_iso_ns

    path = Path(ns.bag)
    if ns.salvage:
        table, report = read_passes_reported(path, ns.topic, salvage=True)
        print(printable(report.salvage.line(path)))
    else:
        if not is_csv(path):
            info = bag_info(path)
            span = (info.end_ns - info.start_ns) / NS_PER_S
            print(f"bag:       {printable(info.path)} ({info.storage})")
            print(f"start:     {format_iso_ns(info.start_ns)}")
            print(f"duration:  {span:.1f} s ({span * NS_PER_S / NS_PER_DAY:.2f} days)")
            print(f"messages:  {info.message_count}")
            record = read_site_record(path)
            print(f"site:      {printable(describe(record)) if record else 'none stored'}")
            for t in info.topics:
                print(f"  {printable(t.name):32s} {printable(t.typename):40s} {t.count}")
            if not any(t.typename == TRAIN_PASS for t in info.topics):
                return 0
        table = read_passes(path, ns.topic)
    if len(table):
        print("\n".join(pass_statistics(table)))
    return 0


def pass_statistics(table) -> list[str]:
    """Lines on a pass table: rate, speed, angle of attack, friction and class mix."""
    from rail_monitor.core.passes import FRICTION_NAMES
    from rail_monitor.core.text import printable
    from rail_monitor.core.timeutil import NS_PER_DAY

    days = max((table.stamp_ns.max() - table.stamp_ns.min()) / NS_PER_DAY, 1e-9)
    states, counts = np.unique(table.friction_state, return_counts=True)
    classes, class_counts = np.unique(table.vehicle_class.astype(str), return_counts=True)
    return [
        f"passes:    {len(table)} ({len(table) / days:.1f} per day)",
        f"speed:     mean {table.speed_mps.mean():.2f} m/s, sd {table.speed_mps.std():.2f} m/s, "
        f"range {table.speed_mps.min():.2f}-{table.speed_mps.max():.2f} m/s",
        f"AoA:       mean {1e3 * table.angle_of_attack_rad.mean():.2f} mrad, "
        f"95th percentile {1e3 * np.percentile(table.angle_of_attack_rad, 95):.2f} mrad",
        "friction:  " + ", ".join(f"{FRICTION_NAMES.get(int(s), s)} {c}" for s, c in zip(states, counts, strict=True)),
        "classes:   " + ", ".join(f"{printable(c)} {n}" for c, n in zip(classes, class_counts, strict=True))]
