"""The graph as separate processes: what ``launch/wayside.launch.py`` starts, as plain data.

The launch file builds its launch_ros Nodes from :data:`PROCESSES`, and the tests start the same
executables with the same parameters from it (ros2launch is not installable everywhere), so the
layout a user launches is the layout tested against the one-process graph and batch mode.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Process:
    """One executable of the graph: its own parameters, and the launch arguments it takes
    (parameter name -> launch argument)."""

    executable: str
    parameters: dict[str, object] = field(default_factory=dict)
    arguments: dict[str, str] = field(default_factory=dict)
    sim_time: bool = True  # runs on pass time (/clock from the source)


# Consumers first: each creates its publishers before it subscribes train_pass, and the source
# waits for all five train_pass subscribers and for the graph to settle before its first pass.
PROCESSES: tuple[Process, ...] = (
    Process("mcap_recorder", arguments={"output": "output"}),
    Process("squeal_risk_model"),
    Process("corrugation_estimator", arguments={"checkpoint_path": "checkpoint"}),
    Process("rolling_noise_predictor"),
    Process("alert_manager"),
    Process("pass_replayer", {"wait_for_subscribers": 5}, {"source": "source", "rate": "rate"}, sim_time=False),
)
SOURCE = "pass_replayer"  # when it exits (a finite history replayed), the whole graph shuts down
FLOAT_ARGUMENTS = ("rate",)  # typed: rate:=10 is 10.0, not an integer the parameter refuses
