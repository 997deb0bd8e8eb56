"""wayside_monitor: the whole graph in one process (one executor), like a component container:
the pass source (replayer of ``source``, or the simulator when ``source`` is empty), the models
(``models:=engine``, the default: site_engine, the one node holding the site engine that batch mode
runs; ``models:=nodes``: corrugation_estimator, rolling_noise_predictor, squeal_risk_model and
alert_manager) and mcap_recorder.
Runs on pass time; exits when the history has been replayed, every model has taken every pass and
the recorder holds every message the nodes published (then a final speed advisory on the final
state); prints a summary.

With ``listen:=true`` it hosts no source: the passes come from other processes (a wayside
detector's driver publishing train_pass), on their own stamps, until SIGINT or SIGTERM; then it
takes what was already sent (``stop_timeout_s``), publishes the advice on the final state and
finishes the bag.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import rclpy
from rclpy.executors import Executor, MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.node import Node

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.node_params import MONITOR_SPECS, SOURCE, MonitorParams
from rail_monitor.core.params import ParamGroups, values_of
from rail_monitor.nodes.alert_manager import AlertManagerNode
from rail_monitor.nodes.base import RailNode, declare
from rail_monitor.nodes.corrugation_estimator import CorrugationEstimatorNode
from rail_monitor.nodes.hosted_models import FourNodes, HostedModels, OneEngine
from rail_monitor.nodes.mcap_recorder import McapRecorder
from rail_monitor.nodes.pass_replayer import PassReplayer
from rail_monitor.nodes.pass_simulator import PassSimulator
from rail_monitor.nodes.process import (
    IDLE_SPIN_TIMEOUT_S,
    CoalescingExecutor,
    asked_for_help,
    destroy_nodes,
    exit_code,
    help_text,
    ros_session,
    shut_down,
    spin_guarded,
)
from rail_monitor.nodes.rolling_noise_predictor import RollingNoisePredictor
from rail_monitor.nodes.site_engine import SiteEngineNode
from rail_monitor.nodes.squeal_risk_model import SquealRiskNode


@dataclass
class MonitorResult:
    published: int
    recorded: dict[str, int]
    bag: str | None
    wall_s: float                     # start to finish, set-up included [s]
    rejected: dict[str, int] = field(default_factory=dict)
    replay_s: float = 0.0             # first pass published (or listening) to the last output recorded [s]
    listened: bool = False            # the passes came from other processes (listen:=true)


class _Settings(RailNode):
    """Holds the process-level parameters (no topics)."""

    def __init__(self) -> None:
        super().__init__("wayside_monitor")
        self.cfg = values_of(MonitorParams, declare(self, (*MONITOR_SPECS, SOURCE)))


def _real_models(layout: str) -> HostedModels:
    if layout == "engine":
        return OneEngine(SiteEngineNode())
    return FourNodes(CorrugationEstimatorNode(), RollingNoisePredictor(), SquealRiskNode(), AlertManagerNode())


def run_graph(args: list[str] | None = None, make_models: Callable[[], HostedModels] | None = None,
              make_recorder: Callable[[], Node] = McapRecorder) -> MonitorResult:
    """Build the graph in this process, replay, drain, shut down; return what happened.

    make_models, make_recorder: the nodes hosted (default: as the ``models`` parameter says; the
    benchmark's no-op graph passes stand-ins with the same topics, types and QoS), the models as
    their layout (nodes.hosted_models).
    """
    # The flow-control profile is for subscribers in other processes (in-process ones are paced exactly).
    with ros_session(args, flow_control=True, default_site=True) as stop:
        nodes: list[Node] = []
        executor = spinner = None
        finished = threading.Event()
        t0 = time.monotonic()
        try:
            settings = _Settings()
            nodes.append(settings)
            if settings.cfg.listen and settings.cfg.source:  # refused before a bag is begun
                raise RailMonitorError("listen:=true takes the passes from other processes: leave source empty")
            recorder = make_recorder() if settings.cfg.record else None
            models = make_models() if make_models is not None else _real_models(settings.cfg.models)
            nodes += ([recorder] if recorder is not None else []) + models.nodes
            source = None
            if not settings.cfg.listen:
                source = PassReplayer() if settings.cfg.source else PassSimulator()
                nodes.append(source)
                hosted = len(models.nodes) + (recorder is not None)
                source.foreign_subscribers = source.cfg.wait_for_subscribers > hosted
                source.cfg = replace(source.cfg, wait_for_subscribers=max(source.cfg.wait_for_subscribers, hosted))
                source.consumed = models.passes_through(recorder, source.pub.topic_name)
            executor = _make_executor(settings.cfg.executor, settings.cfg.threads, settings.cfg.listen)
            for n in nodes:
                executor.add_node(n)
            # Woken for work or by shut_down(executor), not on a short timeout: idle, only the nodes' timers run.
            spinner = threading.Thread(target=spin_guarded, args=(executor, lambda: not finished.is_set()),
                                       kwargs={"timeout_sec": IDLE_SPIN_TIMEOUT_S}, daemon=True)
            spinner.start()
            if source is None:
                return _listen(models, recorder, settings.cfg, stop, t0)
            return _replay(source, models, recorder, settings.cfg, stop, t0)
        finally:
            finished.set()
            if executor is not None:
                shut_down(executor, 2.0)
                if spinner is not None and spinner.is_alive():
                    spinner.join(timeout=5.0)
            for n in reversed(nodes):
                close = getattr(n, "close", None)
                if close is not None:
                    with contextlib.suppress(RailMonitorError):  # already raised (a failed bag)
                        close()
            destroy_nodes(list(reversed(nodes)))


def _replay(source: PassReplayer | PassSimulator, models: HostedModels, recorder: McapRecorder | None,
            cfg: MonitorParams, stop: threading.Event, t0: float) -> MonitorResult:
    """Replay every pass, wait until every model and the recorder took what was published, and
    publish the advice on the final state. After SIGINT or SIGTERM the waits share
    ``stop_timeout_s``: what is taken by then is recorded and the bag finished (no error)."""
    recorded_topics = models.output_topics() | {p.topic_name for p in (source.event_pub, source.measured_pub) if p}
    if recorder is not None:
        _wait(lambda: recorded_topics <= set(recorder.counts), cfg.drain_timeout_s,
              lambda: f"recorder did not subscribe to {sorted(recorded_topics - set(recorder.counts))}")
    t_replay = time.monotonic()
    published = source.run(lambda: not stop.is_set() and source.context.ok())
    stopping = stop.is_set()
    deadline = time.monotonic() + (cfg.stop_timeout_s if stopping else cfg.drain_timeout_s)

    def wait(done: Callable[[], bool], what: Callable[[], str]) -> None:
        _wait(done, max(deadline - time.monotonic(), 0.0), what, raise_error=not stopping)

    wait(lambda: models.took(published) and models.settled(),
         lambda: f"models took {[m.taken for m in models.nodes]} of {published} passes")
    wait(lambda: models.measured_taken() >= source.measurements_sent and models.inputs_taken(),
         lambda: f"models took {models.measured_taken()} of {source.measurements_sent} measurements")
    models.head.publish_advisory()  # the advice on the final state
    sent = {source.pub.topic_name: published}
    for pub, n in ((source.event_pub, source.events_sent), (source.measured_pub, source.measurements_sent)):
        if pub is not None:
            sent[pub.topic_name] = n
    return _finish(models, recorder, sent, wait, published, t0, t_replay)


def _listen(models: HostedModels, recorder: McapRecorder | None, cfg: MonitorParams,
            stop: threading.Event, t0: float) -> MonitorResult:
    """Take the passes other processes publish until SIGINT or SIGTERM; then, within
    stop_timeout_s, the backlog, the advice on the final state and the recorder's catching up."""
    t_listen = time.monotonic()
    stop.wait()
    head = models.head
    deadline = time.monotonic() + cfg.stop_timeout_s

    def wait(done: Callable[[], bool], what: Callable[[], str]) -> None:
        _wait(done, max(deadline - time.monotonic(), 0.0), what, raise_error=False)

    wait(models.settled, lambda: "rolling_noise_predictor still holds passes")
    head.publish_advisory()
    taken = {head.resolve_topic_name("train_pass"): head.taken}  # the recorder takes them too
    return replace(_finish(models, recorder, taken, wait, head.taken, t0, t_listen), listened=True)


def _finish(models: HostedModels, recorder: McapRecorder | None, sent: dict[str, int],
            wait: Callable[[Callable[[], bool], Callable[[], str]], None], published: int, t0: float,
            t_first: float) -> MonitorResult:
    """Wait until the recorder holds every message sent (the models' and ``sent``), finish the bag."""
    recorded: dict[str, int] = {}
    bag = None
    if recorder is not None:
        sent = dict(sent)
        for m in models.nodes:
            sent.update(m.sent)
        wait(lambda: recorder.writer.error or all(recorder.counts.get(t, 0) >= n for t, n in sent.items()),
             lambda: f"recorder got {dict(recorder.counts)} of {sent}")
        if recorder.writer.error:  # e.g. a full disk: say so now, not after the drain timeout
            raise RailMonitorError(recorder.writer.error)
    replay_s = time.monotonic() - t_first
    if recorder is not None:
        bag = str(recorder.close())
        recorded = dict(recorder.counts)
    rejected = {m.get_name(): sum(m.rejected.values()) for m in models.nodes}
    return MonitorResult(published, recorded, bag, time.monotonic() - t0, rejected, replay_s)


def _wait(done: Callable[[], bool], timeout_s: float, what: Callable[[], str], raise_error: bool = True) -> None:
    """Poll done() for at most timeout_s [s]; then RailMonitorError (or, stopping, a warning)."""
    deadline = time.monotonic() + timeout_s
    while not done():
        if time.monotonic() > deadline:
            if raise_error:
                raise RailMonitorError(f"{what()} within {timeout_s:g} s")
            rclpy.logging.get_logger("wayside_monitor").warning(f"stopping: {what()}; the bag keeps what it took")
            return
        time.sleep(0.02)


def _make_executor(kind: str, threads: int, listen: bool) -> Executor:
    if kind == "single_threaded":
        # Listening, passes arrive one at a time: take each one's messages from one wait set. A
        # replay is paced by what the nodes took, and a pause at each wake-up would slow it.
        return CoalescingExecutor() if listen else SingleThreadedExecutor()
    return MultiThreadedExecutor(num_threads=threads)


def parameters() -> ParamGroups:
    """Every parameter of the hosted nodes, each once (for --help)."""
    seen: set[str] = set()
    out = []
    hosted = (McapRecorder, SiteEngineNode, CorrugationEstimatorNode, RollingNoisePredictor, SquealRiskNode,
              AlertManagerNode,
              PassReplayer, PassSimulator)
    for prefix, specs in (("", (*MONITOR_SPECS, SOURCE)), *(g for cls in hosted for g in cls.PARAMETERS)):
        new = tuple(s for s in specs if prefix + s.name not in seen)
        seen |= {prefix + s.name for s in new}
        if new:
            out.append((prefix, new))
    return tuple(out)


def main(args: list[str] | None = None) -> int:
    if asked_for_help(sys.argv if args is None else args):
        print(help_text("wayside_monitor", __doc__, parameters()))
        return 0

    def run() -> int:
        r = run_graph(args)
        print(f"wayside_monitor: {r.published} passes through the graph in {r.wall_s:.1f} s "
              f"({r.published / max(r.replay_s, 1e-9):.0f} passes/s over the {r.replay_s:.1f} s of the "
              + ("listening)" if r.listened else "replay)"))
        if r.bag:
            print(f"recorded {sum(r.recorded.values())} messages to {r.bag}: "
                  + ", ".join(f"{t} {n}" for t, n in sorted(r.recorded.items())))
        return 0

    return exit_code(run)


if __name__ == "__main__":
    sys.exit(main())
