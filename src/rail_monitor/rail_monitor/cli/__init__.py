"""rail-monitor: the command line (site, simulate, info, replay, record, monitor, demo, batch, plan,
report, export, predict, measure).

One module per verb: its arguments, a call into the package's functions (what-ifs, batch mode,
the report, the nodes), and the printing. Node options are generated from the same ParamSpecs
the nodes declare, so --help shows every unit, range and default; they become
``-p name:=value`` ROS arguments. Errors the user can act on are one line on stderr and exit
code 2. :func:`main` takes the arguments and returns the exit code, so the command line is
callable in-process.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from rail_monitor.cli import (
    batch,
    export,
    graph,
    info,
    measure,
    plan,
    predict_audio,
    predict_corrugation,
    predict_noise,
    predict_roughness,
    predict_squeal,
    report,
    simulate,
    site,
)
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.text import printable


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="rail-monitor", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    site.add_parser(sub)
    simulate.add_parser(sub)
    info.add_parser(sub)
    graph.add_parsers(sub)
    s = sub.add_parser("predict", help="run one model on physical inputs")
    models = s.add_subparsers(dest="model", required=True)
    for verb in (predict_squeal, predict_corrugation, predict_noise, predict_roughness, predict_audio):
        verb.add_parser(models)
    measure.add_parser(sub)
    batch.add_parser(sub)
    plan.add_parser(sub)
    report.add_parser(sub)
    export.add_parser(sub)
    _state_defaults_once(p)
    return p


class DefaultsOnceFormatter(argparse.HelpFormatter):
    """Help with each option's default stated once: appended where the option's own text does not
    state it, and there is a value to state."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if ("default" in text or not action.option_strings or action.default in (None, False, argparse.SUPPRESS)
                or isinstance(action.default, bool)):
            return text
        return f"{text} (default: %(default)s)"


def _state_defaults_once(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = DefaultsOnceFormatter
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                _state_defaults_once(sub)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line on argv (default: sys.argv[1:]); returns the exit code."""
    argv = list(sys.argv[1:] if argv is None else argv)
    # Anything from --ros-args on goes to the nodes untouched (e.g. -p executor:=events).
    cut = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    ns = build_parser().parse_args(argv[:cut])
    ns.ros_extra = argv[cut:]
    try:
        return ns.func(ns)
    except RailMonitorError as exc:
        print(f"rail-monitor: error: {printable(exc)}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
