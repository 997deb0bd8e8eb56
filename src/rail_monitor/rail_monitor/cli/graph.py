"""rail-monitor replay, record, monitor and demo: the ROS 2 nodes, started from the command line."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from rail_monitor.bagio.output_folder import beside
from rail_monitor.cli.common import (
    add_site_option,
    add_specs,
    fresh_output,
    print_report,
    ros_args,
    site_file,
    site_values,
)
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.node_params import MONITOR_SPECS, PUBLISH_SPECS, RECORDER_SPECS, REPLAYER_SPECS

# The bundled sample: ros2_ws/run says where the repository is; else the working folder's bags/.
DEFAULT_SAMPLE = Path(os.environ.get("RAIL_MONITOR_HOME", ".")) / "bags" / "sample"


def add_parsers(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("replay", help="run pass_replayer: publish a history on train_pass with /clock")
    s.add_argument("source", help="bag folder, .mcap, .db3 or .csv")
    s.add_argument("--site", help="site parameter file (for site_id)")
    s.add_argument("--namespace", help="site namespace for the topics, e.g. curve_250")
    add_specs(s, PUBLISH_SPECS + REPLAYER_SPECS, skip=("source",))
    s.set_defaults(func=replay)

    s = sub.add_parser("record", help="run mcap_recorder until Ctrl-C or SIGTERM")
    s.add_argument("output", help="bag folder to create")
    s.add_argument("--namespace", help="site namespace (relative topic names resolve under it)")
    add_specs(s, RECORDER_SPECS, skip=("output",))
    s.set_defaults(func=record)

    for name, helptext in (("monitor", "run the whole graph in one process on a history"),
                           ("demo", "the main job: the bundled sample history through the whole graph")):
        s = sub.add_parser(name, help=helptext)
        if name == "monitor":
            s.add_argument("source", help="bag folder, .mcap, .db3 or .csv")
            s.add_argument("--output", help="bag folder to record into (default: <source>_monitor next to it)")
        else:
            s.add_argument("--source", type=Path, default=DEFAULT_SAMPLE, help="history to replay")
            s.add_argument("--output", default="out/demo", help="bag folder to record into")
        add_site_option(s)
        s.add_argument("--namespace", help="site namespace (default: the site_id)")
        s.add_argument("--report", help="report folder (default: <output>_report)")
        s.add_argument("--no-report", action="store_true", help="record only: no summary or report")
        s.add_argument("--overwrite", action="store_true", default=name == "demo",
                       help="replace an existing output folder that rail_monitor created")
        add_specs(s, MONITOR_SPECS + PUBLISH_SPECS + REPLAYER_SPECS,
                  skip=("site_id", "wait_for_subscribers", "wait_timeout_s", "source"))
        s.set_defaults(func=demo if name == "demo" else monitor)


def replay(ns: argparse.Namespace) -> int:
    from rail_monitor.nodes.pass_replayer import main

    return main(ros_args(ns, site_file(ns.site) if ns.site else None, {"source": ns.source}))


def record(ns: argparse.Namespace) -> int:
    from rail_monitor.nodes.mcap_recorder import main

    return main(ros_args(ns, None, {"output": ns.output}))


def monitor(ns: argparse.Namespace) -> int:
    return _monitor_and_report(ns, ns.source)


def demo(ns: argparse.Namespace) -> int:
    if not ns.source.exists():
        raise RailMonitorError(f"{ns.source} not found: run the demo through ros2_ws/run, or give --source")
    return _monitor_and_report(ns, str(ns.source))


def _monitor_and_report(ns: argparse.Namespace, source: str) -> int:
    from rail_monitor.nodes.wayside_monitor import main

    output = ns.output or str(beside(source, "_monitor"))
    fresh_output(Path(output), ns.overwrite, [source])
    if not ns.namespace:
        ns.namespace = str(site_values(ns.site).get("site_id", ""))
    rc = main(ros_args(ns, site_file(ns.site), {"source": source, "output": output, "use_sim_time": True}))
    if rc == 0 and not ns.no_report:
        print_report(output, ns.site, ns.report)
    return rc
