"""pass_simulator: generate realistic, seeded traffic for a site and publish it or write a bag.

mode 'publish': publishes ``train_pass`` and ``/clock`` like pass_replayer (same timing
parameters), and the friction-modifier applicator's start and stop of its schedule on
``friction_applicator``. mode 'bag': writes them straight into a rosbag2 MCAP bag at ``output``.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from rail_monitor.bagio.passes_bag import write_passes_bag
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.friction import ApplicatorEvent
from rail_monitor.core.node_params import MODE_SPECS, ModeParams
from rail_monitor.core.params import values_of
from rail_monitor.core.passes import PassTable
from rail_monitor.core.simulator_params import SIMULATOR_SPECS, simulator_config
from rail_monitor.nodes.base import SITE_PARAMETERS, declare, declare_site
from rail_monitor.nodes.pass_source import PassSourceNode
from rail_monitor.nodes.process import run_node
from rail_monitor.simulation.simulator import applicator_events, simulate


class PassSimulator(PassSourceNode):
    EXECUTABLE = "pass_simulator"
    PARAMETERS = (*PassSourceNode.PARAMETERS, *SITE_PARAMETERS, ("", MODE_SPECS), ("", SIMULATOR_SPECS))

    def __init__(self, **kwargs) -> None:
        super().__init__("pass_simulator", **kwargs)
        self.site = declare_site(self)
        self.sim_cfg = simulator_config(declare(self, SIMULATOR_SPECS))
        self.mode = values_of(ModeParams, declare(self, MODE_SPECS))
        self._table = simulate(self.site, self.sim_cfg)
        self._applicators = applicator_events(self.sim_cfg)
        if self._applicators and self.mode.mode == "publish":
            self.advertise_applicators()

    def passes(self) -> PassTable:
        return self._table

    def applicators(self) -> list[ApplicatorEvent]:
        return self._applicators

    def run(self, ok: Callable[[], bool] | None = None) -> int:
        if self.mode.mode == "publish":
            return super().run(ok)
        if not self.mode.output:
            raise RailMonitorError("mode 'bag' needs parameter 'output' (a bag folder to create)")
        write_passes_bag(self._window(self._table), self.mode.output, self.site.site_id,
                         applicators=self._applicators)
        self.get_logger().info(f"wrote {len(self._table)} passes to {self.mode.output}")
        self.done.set()
        return len(self._table)


def main(args: list[str] | None = None) -> int:
    return run_node(PassSimulator, args, flow_control=True)


if __name__ == "__main__":
    sys.exit(main())
