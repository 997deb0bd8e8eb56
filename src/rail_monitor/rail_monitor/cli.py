"""rail-monitor: command-line front end (simulate, replay, record, monitor, demo, info).

Node options are generated from the same ParamSpecs the nodes declare, so --help shows every
unit, range and default; they become ``-p name:=value`` ROS arguments. Errors the user can act
on are one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rail_monitor.errors import RailMonitorError
from rail_monitor.params import ParamSpec

DEFAULT_SAMPLE = Path("bags/sample")


def _site_file(path: str | None) -> Path:
    if path:
        return Path(path)
    from ament_index_python.packages import get_package_share_directory

    return Path(get_package_share_directory("rail_monitor")) / "config" / "curve_250.yaml"


def _add_specs(parser: argparse.ArgumentParser, specs: Sequence[ParamSpec], skip: Sequence[str] = ()) -> None:
    group = parser.add_argument_group("node parameters (ROS 2 parameter in brackets)")
    for s in specs:
        if s.name in skip:
            continue
        flag = "--" + s.name.replace("_", "-").replace(".", "-")
        extra = f" {s.range_text()}" if (s.low is not None or s.high is not None or s.choices) else ""
        kw: dict = {"dest": "p:" + s.name, "default": None, "metavar": s.kind.__name__.upper(),
                    "help": f"{s.description}{extra} default: {s.default!r} [{s.name}]"}
        if isinstance(s.default, list):
            kw["nargs"] = "*"
        if s.kind is bool:
            kw.update(action=argparse.BooleanOptionalAction, metavar=None)
        else:
            kw["type"] = s.kind
        group.add_argument(flag, **kw)


def _ros_args(ns: argparse.Namespace, site: Path | None, extra: dict[str, object]) -> list[str]:
    """argv for rclpy.init: the site file, the namespace, and -p for every option given."""
    values = {k[2:]: v for k, v in vars(ns).items() if k.startswith("p:") and v is not None}
    values.update({k: v for k, v in extra.items() if v is not None})
    args = ["rail-monitor", *getattr(ns, "ros_extra", []), "--ros-args"]
    if site is not None:
        args += ["--params-file", str(site)]
    if getattr(ns, "namespace", None):
        args += ["-r", f"__ns:=/{ns.namespace.strip('/')}"]
    for name, v in values.items():
        if isinstance(v, bool):
            text = "true" if v else "false"
        elif isinstance(v, list):
            text = "[" + ",".join(f"'{x}'" if isinstance(x, str) else repr(x) for x in v) + "]"
        elif isinstance(v, str):
            text = f"'{v}'" if v else "''"
        else:
            text = repr(v)
        args += ["-p", f"{name}:={text}"]
    return args


# -- subcommands -----------------------------------------------------------------------------
def cmd_simulate(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.csv_io import write_csv
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.simulator import simulate, simulator_config
    from rail_monitor.site import load_parameter_file, site_from_values

    values = load_parameter_file(_site_file(ns.site))
    if ns.days is not None:
        values["simulator.days"] = ns.days
    if ns.seed is not None:
        values["simulator.seed"] = ns.seed
    site = site_from_values(values)
    table = simulate(site, simulator_config(values))
    if not ns.out and not ns.csv:
        raise RailMonitorError("give --out BAG and/or --csv FILE")
    if ns.out:
        if ns.force and Path(ns.out).exists():
            shutil.rmtree(ns.out)
        write_passes_bag(table, ns.out, site.site_id)
        print(f"wrote {len(table)} passes to bag {ns.out}")
    if ns.csv:
        write_csv(table, ns.csv)
        print(f"wrote {len(table)} passes to {ns.csv}")
    return 0


def cmd_info(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.reader import bag_info, is_csv, read_passes
    from rail_monitor.passes import FRICTION_NAMES
    from rail_monitor.timeutil import NS_PER_S, format_iso_ns

    path = Path(ns.bag)
    if not is_csv(path):
        info = bag_info(path)
        span = (info.end_ns - info.start_ns) / NS_PER_S
        print(f"bag:       {info.path} ({info.storage})")
        print(f"start:     {format_iso_ns(info.start_ns)}")
        print(f"duration:  {span:.1f} s ({span / 86400:.2f} days)")
        print(f"messages:  {info.message_count}")
        for t in info.topics:
            print(f"  {t.name:32s} {t.typename:40s} {t.count}")
        if not any(t.typename == "rail_msgs/msg/TrainPass" for t in info.topics):
            return 0
    table = read_passes(path, ns.topic)
    if len(table):
        days = max((table.stamp_ns.max() - table.stamp_ns.min()) / 86400e9, 1e-9)
        print(f"passes:    {len(table)} ({len(table) / days:.1f} per day)")
        print(f"speed:     mean {table.speed_mps.mean():.2f} m/s, sd {table.speed_mps.std():.2f} m/s, "
              f"range {table.speed_mps.min():.2f}-{table.speed_mps.max():.2f} m/s")
        print(f"AoA:       mean {1e3 * table.angle_of_attack_rad.mean():.2f} mrad, "
              f"95th percentile {1e3 * np.percentile(table.angle_of_attack_rad, 95):.2f} mrad")
        states, counts = np.unique(table.friction_state, return_counts=True)
        mix = zip(states, counts, strict=True)
        print("friction:  " + ", ".join(f"{FRICTION_NAMES.get(int(s), s)} {c}" for s, c in mix))
        classes, counts = np.unique(table.vehicle_class.astype(str), return_counts=True)
        print("classes:   " + ", ".join(f"{c} {n}" for c, n in zip(classes, counts, strict=True)))
    return 0


def cmd_replay(ns: argparse.Namespace) -> int:
    from rail_monitor.nodes.pass_replayer import main

    return main(_ros_args(ns, _site_file(ns.site) if ns.site else None, {"source": ns.source}))


def cmd_record(ns: argparse.Namespace) -> int:
    from rail_monitor.nodes.mcap_recorder import main

    return main(_ros_args(ns, None, {"output": ns.output}))


def _monitor(ns: argparse.Namespace, source: str, output: str | None) -> int:
    from rail_monitor.nodes.wayside_monitor import main

    if output and Path(output).exists():
        if not ns.overwrite:
            raise RailMonitorError(f"{output} exists; remove it or pass --overwrite")
        shutil.rmtree(output)
    site = _site_file(ns.site)
    if not ns.namespace:
        from rail_monitor.site import load_parameter_file

        ns.namespace = str(load_parameter_file(site).get("site_id", ""))
    return main(_ros_args(ns, site, {"source": source, "output": output, "use_sim_time": True}))


def cmd_monitor(ns: argparse.Namespace) -> int:
    return _monitor(ns, ns.source, ns.output)


def cmd_demo(ns: argparse.Namespace) -> int:
    if not ns.source.exists():
        raise RailMonitorError(f"{ns.source} not found: run the demo from the repository's top folder")
    return _monitor(ns, str(ns.source), ns.output)


def build_parser() -> argparse.ArgumentParser:
    from rail_monitor.nodes.mcap_recorder import RECORDER_SPECS
    from rail_monitor.nodes.pass_replayer import REPLAYER_SPECS
    from rail_monitor.nodes.pass_source import PUBLISH_SPECS
    from rail_monitor.nodes.wayside_monitor import MONITOR_SPECS

    p = argparse.ArgumentParser(prog="rail-monitor", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("simulate", help="generate a seeded pass history for a site into a bag and/or CSV")
    s.add_argument("--site", help="site parameter file (default: the shipped curve_250.yaml)")
    s.add_argument("--out", help="bag folder to create (MCAP)")
    s.add_argument("--csv", help="CSV file to write")
    s.add_argument("--days", type=float, help="override simulator.days [day]")
    s.add_argument("--seed", type=int, help="override simulator.seed [-]")
    s.add_argument("--force", action="store_true", help="replace an existing bag folder")
    s.set_defaults(func=cmd_simulate)

    s = sub.add_parser("info", help="summarise a bag or CSV: topics, counts, time span, pass statistics")
    s.add_argument("bag", help="bag folder, .mcap, .db3 or .csv")
    s.add_argument("--topic", help="TrainPass topic to summarise (default: the only one)")
    s.set_defaults(func=cmd_info)

    s = sub.add_parser("replay", help="run pass_replayer: publish a history on train_pass with /clock")
    s.add_argument("source", help="bag folder, .mcap, .db3 or .csv")
    s.add_argument("--site", help="site parameter file (for site_id)")
    s.add_argument("--namespace", help="site namespace for the topics, e.g. curve_250")
    _add_specs(s, PUBLISH_SPECS + REPLAYER_SPECS, skip=("source",))
    s.set_defaults(func=cmd_replay)

    s = sub.add_parser("record", help="run mcap_recorder until Ctrl-C or SIGTERM")
    s.add_argument("output", help="bag folder to create")
    s.add_argument("--namespace", help="site namespace (relative topic names resolve under it)")
    _add_specs(s, RECORDER_SPECS, skip=("output",))
    s.set_defaults(func=cmd_record)

    for name, helptext in (("monitor", "run the whole graph in one process on a history"),
                           ("demo", "the main job: the bundled sample history through the whole graph")):
        s = sub.add_parser(name, help=helptext)
        if name == "monitor":
            s.add_argument("source", help="bag folder, .mcap, .db3 or .csv")
            s.add_argument("--output", help="bag folder to record into")
        else:
            s.add_argument("--source", type=Path, default=DEFAULT_SAMPLE, help="history to replay")
            s.add_argument("--output", default="out/demo", help="bag folder to record into")
        s.add_argument("--site", help="site parameter file (default: the shipped curve_250.yaml)")
        s.add_argument("--namespace", help="site namespace (default: the site_id)")
        s.add_argument("--overwrite", action="store_true", default=name == "demo",
                       help="replace an existing output folder")
        _add_specs(s, MONITOR_SPECS + PUBLISH_SPECS, skip=("site_id", "wait_for_subscribers", "wait_timeout_s"))
        s.set_defaults(func=cmd_demo if name == "demo" else cmd_monitor)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    # Anything from --ros-args on goes to the nodes untouched (e.g. -p executor:=events).
    cut = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    ns = build_parser().parse_args(argv[:cut])
    ns.ros_extra = argv[cut:]
    try:
        return ns.func(ns)
    except RailMonitorError as exc:
        print(f"rail-monitor: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
