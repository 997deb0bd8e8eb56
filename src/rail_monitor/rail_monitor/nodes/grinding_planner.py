"""grinding_planner: a network's grinding programme, re-planned whenever a site's outlook changes.

Takes every rail_msgs/GrindingOutlook topic as it appears (each site's ``grinding/outlook``, made
by its site_engine or corrugation_estimator on each survey, grinding or indirect observation
applied), or the ``topics`` named, and re-plans the programme over the newest outlook of every
site heard (rail_monitor.economics.replan: the months to visit each site over ``years`` at least
expected cost, each gap's risk held to ``risk_limit``, within ``capacity`` visits a month and
``budget_per_year``; each solve stopped at ``time_limit_s`` with the best programme found).
Publishes each programme on ``grinding/programme`` (rail_msgs/GrindingProgramme, latched: a late
subscriber gets the current one). An outlook older than one already taken from its site changes
nothing; one that cannot be read or planned is counted on /diagnostics and the programme stays as
it was. ``rail-monitor plan --replan`` runs the same re-plans over the sites' histories.
"""

from __future__ import annotations

import sys
from collections import Counter
from typing import Any

from rclpy.qos import QoSProfile

from rail_monitor.codec.cdr import message_view
from rail_monitor.core.node_params import PLANNER_SPECS, PlannerParams
from rail_monitor.core.timeutil import format_iso_ns
from rail_monitor.economics.replan import Replan, Replanner
from rail_monitor.messages.economics_fields import grinding_programme_fields, outlook_from_msg
from rail_monitor.messages.topics import OPTIONAL_TOPICS, PROGRAMME_TOPIC
from rail_monitor.nodes.base import Diagnostics, Sent, announce
from rail_monitor.nodes.convert import message_class
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import profile
from rail_monitor.nodes.topic_tap import TapNode, TopicTap

OUTLOOK_TYPE = OPTIONAL_TOPICS["grinding/outlook"][0]


class GrindingPlanner(TapNode):
    EXECUTABLE = "grinding_planner"
    PARAMETERS = (("", PLANNER_SPECS),)
    CONFIG = PlannerParams

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        c = self.cfg
        self.planner = Replanner(c.years, c.capacity, c.budget_per_year, c.risk_limit, c.pull_forward_months,
                                 c.time_limit_s)
        topic, typename, qos = PROGRAMME_TOPIC
        self.pub = self.create_publisher(message_class(typename), topic, profile(qos))
        self.sent = Sent()
        self.counts: Counter[str] = Counter()
        self.last: Replan | None = None
        self.tap = TopicTap(self, c.topics, c.discovery_period_s, self._on_topic, self._on_messages,
                            types=(OUTLOOK_TYPE,))
        Diagnostics(self, self.diagnostic_values)
        self.tap.discover()
        announce(self, years=c.years, capacity=c.capacity, risk_limit=c.risk_limit)

    def _on_topic(self, topic: str, typename: str, offered: list[QoSProfile]) -> None:
        self.get_logger().info(f"planning on {topic}")

    def _on_messages(self, topic: str, msgs: list[bytes]) -> None:
        for data in msgs:
            try:
                stamp, outlook = outlook_from_msg(message_view(OUTLOOK_TYPE, data))
                replan = self.planner.take(stamp, outlook)
            except Exception as exc:  # one bad outlook costs its own re-plan, never the node
                self.counts[f"outlook refused: {type(exc).__name__}"] += 1
                self.get_logger().warning(f"{topic}: outlook not planned on: {str(exc).splitlines()[0]}")
                continue
            if replan is None:
                self.counts["outlooks older than their site's newest"] += 1
                continue
            self.counts["re-plans"] += 1
            self.last = replan
            self.sent.publish(self.pub, grinding_programme_fields(replan))

    def diagnostic_values(self) -> dict[str, Any]:
        values: dict[str, Any] = {"sites": len(self.planner.latest), "outlook topics": len(self.tap.subs),
                                  **self.counts}
        if self.last is not None:
            p = self.last.programme
            values.update({"programme start": format_iso_ns(self.last.rules.start_ns),
                           "expected cost": f"{p.expected_cost.sum():.6g}",
                           "visits": sum(len(v) for v in p.visits), "solver": p.status})
        return values


def main(args: list[str] | None = None) -> int:
    return run_node(GrindingPlanner, args)


if __name__ == "__main__":
    sys.exit(main())
