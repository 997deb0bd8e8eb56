"""pass_replayer: replay TrainPass history from a rosbag2 bag (MCAP or sqlite3) or a CSV file.

Publishes ``train_pass`` (rail_msgs/TrainPass), the bag's roughness surveys and grinding events
on ``roughness_survey`` (each just before the first pass stamped later than it), its measured
pass-bys on ``noise/measured`` (each after its pass), its friction-modifier applicator's starts and
stops on ``friction_applicator`` (as surveys; a refused one is logged), and ``/clock``;
exits 0 when done. See
rail_monitor.core.node_params.PUBLISH_SPECS for timing, offsets and flow control.
"""

from __future__ import annotations

import sys

from rail_monitor.bagio.reader import read_applicators, read_history_inputs, read_passes_reported
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.friction import ApplicatorEvent
from rail_monitor.core.node_params import REPLAYER_SPECS, ReplayerParams
from rail_monitor.core.params import values_of
from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.measured.records import Measurement
from rail_monitor.nodes.base import declare
from rail_monitor.nodes.pass_source import PassSourceNode
from rail_monitor.nodes.process import run_node


class PassReplayer(PassSourceNode):
    EXECUTABLE = "pass_replayer"
    PARAMETERS = (*PassSourceNode.PARAMETERS, ("", REPLAYER_SPECS))

    def __init__(self, **kwargs) -> None:
        super().__init__("pass_replayer", **kwargs)
        self.src = values_of(ReplayerParams, declare(self, REPLAYER_SPECS))
        if not self.src.source:
            raise RailMonitorError("parameter 'source' is empty: give a bag or CSV path (-p source:=PATH)")
        self.skipped = 0
        self._table = self._load()  # read up front: a bad file fails before anything is published
        self._events, self._measured = read_history_inputs(self.src.source, self.src.measured_source or None,
                                                           self.src.skip_bad_rows, self.src.salvage,
                                                           [p for p in self.src.surveys_source if p])
        self._applicators, refused = read_applicators(self.src.source, self.src.salvage)
        for why, n in sorted(refused.items()):
            self.get_logger().warning(f"{self.src.source}: {n} friction applicator event(s) left out: {why}")
        if self._events:
            self.advertise_events()
        if self._applicators:
            self.advertise_applicators()
        if self._measured:
            self.advertise_measurements()

    def _load(self) -> PassTable:
        table, report = read_passes_reported(self.src.source, self.src.source_topic or None, self.src.skip_bad_rows,
                                             salvage=self.src.salvage)
        if report.salvage is not None:
            self.get_logger().info(report.salvage.line(self.src.source))
        self.skipped = len(report.skipped_rows)
        if self.skipped:
            self.get_logger().warning(f"{self.src.source}: {self.skipped} malformed row(s) left out")
        return table

    def passes(self) -> PassTable:
        return self._table

    def events(self) -> list[MaintenanceEvent]:
        return self._events

    def applicators(self) -> list[ApplicatorEvent]:
        return self._applicators

    def measurements(self) -> list[Measurement]:
        return self._measured


def main(args: list[str] | None = None) -> int:
    return run_node(PassReplayer, args, flow_control=True)


if __name__ == "__main__":
    sys.exit(main())
