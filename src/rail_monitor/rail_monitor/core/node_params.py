"""Parameters of the graph's nodes that belong to no model: pass sources, the recorder, the
one-process graph, batching, checkpoints.

Pure specs (no rclpy), so the site-file check (:mod:`rail_monitor.site_file`), the command
line's options and the nodes share one list of names, units and ranges.
"""

from __future__ import annotations

from dataclasses import dataclass

from rail_monitor.core.params import ParamSpec
from rail_monitor.core.site import SITE_ID

# Pass sources (pass_replayer, pass_simulator): what they publish and how fast.
PUBLISH_SPECS: tuple[ParamSpec, ...] = (
    SITE_ID,  # header.frame_id of every pass
    ParamSpec("rate", 0.0, "Replay speed: 0 as fast as the graph takes it, 1 recorded timing, "
              "k k-times faster [-].", 0.0, 1.0e9),
    ParamSpec("start_offset_s", 0.0, "Skip passes earlier than the first pass plus this [s].", 0.0, 1.0e10),
    ParamSpec("end_offset_s", 0.0, "Stop after the first pass plus this; 0: to the end [s].", 0.0, 1.0e10),
    ParamSpec("publish_clock", True, "Publish /clock with pass time (nodes use use_sim_time)."),
    ParamSpec("clock_period_s", 0.1, "Wall time between /clock ticks while waiting for the next pass [s].",
              0.001, 60.0),
    ParamSpec("wait_for_subscribers", 1, "Wait for this many train_pass subscribers (then for the graph to settle) "
              "before the first pass, and at the end for them to take every pass; 1: a recorder or one model "
              "started first loses nothing; 0: start at once [-].", 0, 1000),
    ParamSpec("wait_timeout_s", 30.0, "Give up waiting for subscribers after this [s].", 0.0, 3600.0),
    ParamSpec("ack_batch", 100, "Passes published between flow-control checks (below the publisher's "
              "QoS depth of 1000) [-].", 1, 999),
    ParamSpec("ack_timeout_s", 60.0, "Longest wait for subscribers to catch up before the replay fails [s].",
              0.1, 3600.0),
    ParamSpec("max_backlog", 2000, "In one process: most passes published but not yet taken by the slowest "
              "hosted subscriber (below their queue of 10000) [-].", 1, 9000),
    ParamSpec("progress", True, "Show a progress bar on stderr."),
)


# pass_replayer: where the history comes from.
SOURCE = ParamSpec("source", "", "History to replay: a bag folder, an .mcap or .db3 file, or a .csv export.")
REPLAYER_SPECS: tuple[ParamSpec, ...] = (
    SOURCE,
    ParamSpec("source_topic", "", "TrainPass topic in the bag; empty: its only TrainPass topic."),
    ParamSpec("skip_bad_rows", False, "CSV: leave malformed rows out (counted) instead of failing."),
    ParamSpec("salvage", False, "MCAP: read the passes in every complete chunk of a file cut off mid-write "
              "(a killed recorder, a full disk) instead of failing."),
    ParamSpec("measured_source", "", "Measured pass-bys to replay: a noise station's CSV or a bag; empty: the "
              "source bag's own (none for a CSV source)."),
    ParamSpec("surveys_source", [""], "Bags of roughness surveys (or grinding events) to replay with the source's "
              "own, e.g. from rail-monitor measure roughness --survey-bag; empty: none."),
)


# pass_simulator: publish into the graph or write a bag.
MODE_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("mode", "publish", "publish: into the graph; bag: write a bag at 'output' and exit.",
              choices=("publish", "bag")),
    ParamSpec("output", "", "Bag folder to write in mode 'bag' (must not exist)."),
)


# After SIGINT or SIGTERM, the longest a process takes what was already delivered before it
# finishes its bag and exits 0 (a supervisor should allow this plus a few seconds).
STOP_TIMEOUT = ParamSpec("stop_timeout_s", 5.0, "After SIGINT or SIGTERM: the longest wait for messages already "
                         "sent before the bag is finished and the process exits [s].", 0.0, 300.0)

# The recorder and the Foxglove server: how often they look for new topics.
DISCOVERY_PERIOD = ParamSpec("discovery_period_s", 0.2, "How often to look for new topics [s].", 0.01, 60.0)

# mcap_recorder.
RECORDER_SPECS: tuple[ParamSpec, ...] = (
    STOP_TIMEOUT,
    ParamSpec("output", "", "Bag folder to create; empty: rail_monitor_<UTC time> in the working folder."),
    ParamSpec("site_file", "", "Site file stored with the bag (its text, name, SHA-256 and the software version); "
              "empty: the first --params-file of the process; none given: no site is stored."),
    ParamSpec("topics", [""], "Topics to record (absolute or relative to the namespace); empty: every "
              "rail_msgs topic and /diagnostics."),
    ParamSpec("compression", "zstd", "Chunk compression.", choices=("zstd", "none")),
    ParamSpec("chunk_size", 1 << 20, "Uncompressed bytes of messages per chunk [bytes].", 1024, 1 << 30),
    ParamSpec("max_bag_size", 0, "Start a new file past this size; 0: never [bytes].", 0, 1 << 50),
    ParamSpec("max_bag_duration_s", 0.0, "Start a new file past this span of log time; 0: never [s].", 0.0, 1.0e9),
    ParamSpec("max_total_bytes", 0, "Disk budget of the bag: delete the oldest finished files to stay within it "
              "(needs max_bag_size; at least twice max_bag_size + chunk_size + 64 KiB); 0: no limit [bytes].",
              0, 1 << 50),
    ParamSpec("max_age_s", 0.0, "Delete finished files whose last message is older than this before the newest "
              "(needs a split); 0: keep all [s].", 0.0, 1.0e10),
    ParamSpec("flush_period_s", 5.0, "Close the open chunk at least this often (bounds loss on a kill) [s].",
              0.0, 3600.0),
    ParamSpec("log_time", "receive", "Log time of a message: receive = the node clock at receipt, as rosbag2 "
              "records (pass time on sim time), header = its header.stamp (messages without one take the clock).",
              choices=("receive", "header")),
    DISCOVERY_PERIOD,
)


# foxglove_server: the live view.
FOXGLOVE_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("host", "127.0.0.1", "Address the Foxglove WebSocket server listens on (0.0.0.0: every interface)."),
    ParamSpec("port", 8765, "Its TCP port; 0: any free port (stated in the start-up line) [-].", 0, 65535),
    ParamSpec("topics", [""], "Topics to serve (absolute or relative to the namespace); empty: every rail_msgs "
              "topic and /diagnostics."),
    DISCOVERY_PERIOD,
)


# grinding_planner: a network's grinding programme, re-planned on each site's outlook.
PLANNER_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("years", 5.0, "The programme's horizon from the newest pass counted at any site [year].", 0.1, 50.0),
    ParamSpec("capacity", 0, "Most site visits in a month (0: no limit) [-].", 0, 100000),
    ParamSpec("budget_per_year", 0.0, "Most preventive grinding cost in a programme year (0: no limit) "
              "[cost unit].", 0.0, 1.0e15),
    ParamSpec("risk_limit", 0.1, "Most chance a site's worst band passes its threshold before its visit [-].",
              0.001, 0.999),
    ParamSpec("pull_forward_months", 6, "Months a first visit may come before the due date's 0.1 % quantile "
              "[month].", 0, 120),
    ParamSpec("time_limit_s", 10.0, "Longest a re-plan's solve may take; at the limit the best programme found is "
              "published, its status saying so (a capacity that binds makes the solve hard) [s].", 0.1, 3600.0),
    ParamSpec("topics", [""], "Outlook topics to plan on (absolute or relative to the namespace); empty: every "
              "rail_msgs/GrindingOutlook topic, each site's grinding/outlook."),
    DISCOVERY_PERIOD,
)

# wayside_monitor: the one-process graph.
MONITOR_SPECS: tuple[ParamSpec, ...] = (
    STOP_TIMEOUT,
    ParamSpec("record", True, "Host an mcap_recorder for every output topic."),
    ParamSpec("listen", False, "Take train_pass (and surveys, measured pass-bys) from other processes, a wayside "
              "detector's driver, instead of replaying source or simulating; run until SIGINT or SIGTERM."),
    ParamSpec("drain_timeout_s", 60.0, "After the replay, wait at most this for the recorder to catch up [s].",
              0.0, 3600.0),
    ParamSpec("executor", "single_threaded", "Executor hosting the nodes: single_threaded, or multi_threaded "
              "(like a component container; measured 30x slower here on the sample: rclpy's thread pool costs more "
              "than it gains for Python callbacks under the GIL).", choices=("single_threaded", "multi_threaded")),
    ParamSpec("threads", 4, "Threads of the multi_threaded executor [-].", 1, 64),
    ParamSpec("models", "engine", "The models hosted: engine (one site_engine node, the site engine batch mode "
              "runs, each backlog of passes read once) or nodes (the four model nodes of the separate-process "
              "layout, each reading every pass).", choices=("engine", "nodes")),
)


# Every node that takes train_pass.
BATCH_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("max_batch", 200, "Most queued train passes a callback takes and handles at once (1: one by one) [-].",
              1, 10_000),
    ParamSpec("log_throttle_s", 5.0, "Least time between two log lines of one kind about bad input (rejected "
              "passes, refused messages); may be changed while the node runs [s].", 0.0, 3600.0, tunable=True),
)


# corrugation_estimator: checkpoints and publishing periods.
ESTIMATOR_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("checkpoint_path", "", "File the state is checkpointed to and resumed from ('' : none)."),
    ParamSpec("checkpoint_every_passes", 100, "Counted passes between checkpoints (checked after each "
              "callback's passes: a backlog taken at once is checkpointed at its end) [-].", 1, 10**9),
    ParamSpec("state_period_s", 0.0, "Least wall time between corrugation/state messages [s] (0: every pass).",
              0.0, 86_400.0),
    ParamSpec("advisory_period_s", 60.0, "Wall time between speed advisories [s].", 0.01, 86_400.0),
)


# rolling_noise_predictor: waiting for the corrugation state of a pass.
PREDICTOR_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("state_wait_s", 5.0, "Longest wall time a pass waits for the corrugation state that includes it; "
              "0: take the latest state at once (running without a corrugation_estimator) [s].", 0.0, 3600.0),
)


# Every pass source and consumer, and batch: how far a pass may lie ahead. A pass past the margin
# is rejected (a source leaves it out) and moves no state: one wrong stamp (a detector clock in
# 2038) must not freeze the corrugation history, whose passes must come in time order.
STAMP_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("max_ahead_of_stream_s", 366 * 86_400.0, "Reject a pass stamped more than this after the newest "
              "pass taken before it (a longer outage needs a larger value) [s].", 1.0, 1.0e10),
    ParamSpec("max_ahead_of_clock_s", 86_400.0, "Without use_sim_time: reject a pass stamped more than this after "
              "the node's clock [s].", 1.0, 1.0e10),
)


# Their checked values, by attribute (rail_monitor.core.params.values_of; tests/core/test_params.py holds
# each class's fields to its specs).
@dataclass(frozen=True)
class PublishParams:
    """A pass source's publishing parameters."""

    site_id: str
    rate: float
    start_offset_s: float
    end_offset_s: float
    publish_clock: bool
    clock_period_s: float
    wait_for_subscribers: int
    wait_timeout_s: float
    ack_batch: int
    ack_timeout_s: float
    max_backlog: int
    progress: bool


@dataclass(frozen=True)
class ReplayerParams:
    """pass_replayer's history parameters."""

    source: str
    source_topic: str
    skip_bad_rows: bool
    salvage: bool
    measured_source: str
    surveys_source: list[str]


@dataclass(frozen=True)
class ModeParams:
    """pass_simulator's mode parameters."""

    mode: str
    output: str


@dataclass(frozen=True)
class RecorderParams:
    """mcap_recorder's parameters."""

    stop_timeout_s: float
    output: str
    site_file: str
    topics: list[str]
    compression: str
    chunk_size: int
    max_bag_size: int
    max_bag_duration_s: float
    max_total_bytes: int
    max_age_s: float
    flush_period_s: float
    log_time: str
    discovery_period_s: float


@dataclass(frozen=True)
class MonitorParams:
    """wayside_monitor's process parameters."""

    stop_timeout_s: float
    record: bool
    listen: bool
    drain_timeout_s: float
    executor: str
    threads: int
    models: str
    source: str


@dataclass(frozen=True)
class StampParams:
    """The stamp plausibility margins."""

    max_ahead_of_stream_s: float
    max_ahead_of_clock_s: float


@dataclass(frozen=True)
class PlannerParams:
    """grinding_planner's parameters."""

    years: float
    capacity: int
    budget_per_year: float
    risk_limit: float
    pull_forward_months: int
    time_limit_s: float
    topics: list[str]
    discovery_period_s: float


@dataclass(frozen=True)
class FoxgloveParams:
    """foxglove_server's parameters."""

    host: str
    port: int
    topics: list[str]
    discovery_period_s: float


@dataclass(frozen=True)
class EstimatorParams:
    """corrugation_estimator's own parameters."""

    checkpoint_path: str
    checkpoint_every_passes: int
    state_period_s: float
    advisory_period_s: float
