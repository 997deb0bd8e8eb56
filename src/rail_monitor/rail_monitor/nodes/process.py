"""One process of the graph: its session (rclpy, signals, params files checked), how it spins
(surviving any one callback's exception), how it stops, --help, and the main() of every
single-node executable."""

from __future__ import annotations

import contextlib
import faulthandler
import gc
import signal
import sys
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import rclpy
from rclpy.executors import ExternalShutdownException, ShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from rail_monitor.core.errors import ConfigError, RailMonitorError
from rail_monitor.core.params import ParamGroups, help_lines


def asked_for_help(argv: Sequence[str]) -> bool:
    """Whether -h or --help comes before any --ros-args."""
    head = list(argv)[: list(argv).index("--ros-args")] if "--ros-args" in argv else list(argv)
    return "-h" in head or "--help" in head


def help_text(executable: str, doc: str | None, groups: ParamGroups) -> str:
    """What --help prints: the executable's summary, how to set parameters, then every parameter."""
    summary = (doc or "").strip().split("\n\n")[0]
    return "\n".join([f"usage: {executable} [--ros-args -p NAME:=VALUE ... --params-file SITE.yaml ...]", "",
                      summary, "", "parameters:", *help_lines(groups), ""])


STOP_HANG_S = 20.0  # a process still stopping after this long prints its threads' stacks
TEARDOWN_HANG_S = 10.0  # outputs closed, a teardown (nodes destroyed, rclpy shut down) this long ends the process

# Exceptions that escaped a callback in this process, by cause: rclpy's own handlers raise on some
# messages (its /clock subscription on a negative time), and no single message may stop a node.
CALLBACK_ERRORS: Counter[str] = Counter()


# After a wake-up that found work, a process waits this long before it waits for more, so that the
# messages of one pass (its TrainPass, state and outputs arrive within a few ms) are taken from one
# wait set: rclpy rebuilds the wait set at every wake-up, which at 100 passes/s arriving one at a
# time was most of a node's CPU. It adds at most this to a message's latency, and nothing when idle.
COALESCE_S = 0.005


class CoalescingExecutor(SingleThreadedExecutor):
    """rclpy's single-threaded executor that pauses COALESCE_S before a wait when the last wait
    found work (the executor of every single-node executable). It wraps rclpy's wait generator
    (``_wait_for_ready_callbacks``, rclpy 7.1 as pinned), the one place a new wait begins."""

    def __init__(self, coalesce_s: float = COALESCE_S, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.coalesce_s = coalesce_s
        self._had_work = False

    def _wait_for_ready_callbacks(self, *args: Any, **kwargs: Any) -> Any:
        if self._had_work and self.coalesce_s > 0:
            time.sleep(self.coalesce_s)
        self._had_work = False
        for ready in super()._wait_for_ready_callbacks(*args, **kwargs):
            self._had_work = True
            yield ready


def spin_once_guarded(executor: Any, timeout_sec: float) -> bool:
    """executor.spin_once, with an exception out of a callback counted in CALLBACK_ERRORS and
    logged; False once the context is shut down (stop spinning)."""
    try:
        executor.spin_once(timeout_sec=timeout_sec)
    except (ExternalShutdownException, ShutdownException):
        return False
    except Exception as exc:  # any one message's failure
        why = f"{type(exc).__name__}: {(str(exc).splitlines() or [''])[0]}"
        CALLBACK_ERRORS[why] += 1
        rclpy.logging.get_logger("rail_monitor").error(f"callback failed, going on: {why}",
                                                      throttle_duration_sec=5.0)
    return executor.context.ok()


def shut_down(executor: Any, timeout_sec: float) -> None:
    """executor.shutdown, then a garbage collection before any node is destroyed.

    rclpy's executor keeps a generator that may be suspended inside the block holding its
    entities' handles (it yields a ready waitable, e.g. a QoS event, from there). Shutdown drops
    it, but a reference cycle can keep it alive, and Node.destroy_node then waits for those handles
    while holding the GIL, so no collection can ever free them: the process spins forever (seen
    after SIGINT: 94 % of a core for 18 minutes). Collecting first closes the generator."""
    executor.shutdown(timeout_sec=timeout_sec)
    gc.collect()


def destroy_nodes(nodes: Sequence[Node]) -> None:
    """Destroy the nodes once their outputs are closed, with a deadline on the rest of the teardown.

    Node.destroy_node can block for good inside rcl or the DDS implementation (seen on a loaded
    machine: a node's participant deletion never returning after SIGINT, its spinner already
    stopped). From here to the end of the ROS session, a teardown still under way after
    TEARDOWN_HANG_S prints every thread's stack and ends the process with exit code 1.
    faulthandler's watchdog is a C thread, so it fires even when the hang holds the interpreter
    lock. Nothing is lost: every output was closed before this call."""
    _watchdog(TEARDOWN_HANG_S, exit_after=True)
    for n in nodes:
        n.destroy_node()


def _watchdog(seconds: float, exit_after: bool) -> None:
    """After seconds, every thread's stack to the process's standard error (the file descriptor,
    whatever sys.stderr was replaced by), and with exit_after the process ends (exit code 1)."""
    with contextlib.suppress(AttributeError, ValueError, OSError):  # no standard error: no watchdog
        faulthandler.dump_traceback_later(seconds, exit=exit_after, file=sys.__stderr__)


def spin_guarded(executor: Any, ok: Callable[[], bool], timeout_sec: float = 0.1) -> None:
    """Spin until ok() is False or the context shuts down, surviving any one callback's exception
    (:func:`spin_once_guarded`): the executor.spin of every executable (make ok() False before
    shutting the executor down)."""
    while ok() and spin_once_guarded(executor, timeout_sec):
        pass


def use_flow_control_profile() -> None:
    """Load the package's Fast DDS profile (short writer heartbeat) unless one is set already.

    Call before rclpy.init: Fast DDS reads the variable when the participant is created.
    """
    import os

    from ament_index_python.packages import get_package_share_directory

    if "FASTRTPS_DEFAULT_PROFILES_FILE" not in os.environ:
        os.environ["FASTRTPS_DEFAULT_PROFILES_FILE"] = os.path.join(
            get_package_share_directory("rail_monitor"), "config", "fastdds_flow_control.xml")


def params_files(argv: Sequence[str]) -> list[str]:
    """The files of every ``--params-file`` among the ROS arguments of a command line, in order."""
    out, in_ros = [], False
    for i, arg in enumerate(argv):
        if arg == "--ros-args":
            in_ros = True
        elif arg == "--":
            in_ros = False
        elif in_ros and arg == "--params-file" and i + 1 < len(argv):
            out.append(argv[i + 1])
    return out


# The --params-file arguments of this process's session, in order (the recorder stores the first
# one, the site file, with its bag), and the shipped site file if the session added it.
SESSION_PARAMS_FILES: list[str] = []
SESSION_DEFAULT_SITE: list[str] = []
# Guard-condition triggers that wake a spinning executor when the session is asked to stop.
WAKERS: list[Callable[[], None]] = []
IDLE_SPIN_TIMEOUT_S = 1.0  # the longest an idle spinner sleeps without work or a wake-up


@contextlib.contextmanager
def ros_session(args: list[str] | None = None, flow_control: bool = False,
                default_site: bool = False) -> Iterator[threading.Event]:
    """rclpy initialised for one process, with SIGINT and SIGTERM setting the event it yields
    instead of rclpy's handler (which would shut the context down at once, before a node could
    take what DDS already delivered). Shut down on exit.

    flow_control: load the package's Fast DDS profile (see use_flow_control_profile).
    default_site: without any --params-file, read the shipped site file (the start-up line says
    so), so that a model node started bare knows the same rolling stock as the command line's
    default.
    """
    from rail_monitor.site_file import check_parameter_file, shipped_site_file

    if flow_control:
        use_flow_control_profile()
    args = list(sys.argv if args is None else args)
    if default_site and not params_files(args):
        shipped = str(shipped_site_file())
        args += ["--ros-args", "--params-file", shipped]
        SESSION_DEFAULT_SITE[:] = [shipped]
    SESSION_PARAMS_FILES[:] = params_files(args)
    for path in SESSION_PARAMS_FILES:
        check_parameter_file(path)
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:  # rcl refuses unreadable params files and malformed -p values at init
        raise ConfigError(f"cannot start: {(str(exc).strip().splitlines() or [type(exc).__name__])[-1]}") from None
    stop = threading.Event()

    def on_signal(*_: object) -> None:
        stop.set()
        for wake in list(WAKERS):
            wake()
        # A stop still under way after STOP_HANG_S is a hang in rcl or a node: every thread's stack
        # goes to stderr, to say where (the process goes on; a supervisor's kill ends it).
        _watchdog(STOP_HANG_S, exit_after=False)

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield stop
    finally:
        SESSION_PARAMS_FILES.clear()
        SESSION_DEFAULT_SITE.clear()
        rclpy.try_shutdown()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        faulthandler.cancel_dump_traceback_later()


def exit_code(main: Callable[[], int]) -> int:
    """main()'s exit code; a RailMonitorError is one line on stderr and exit code 2, not a traceback."""
    try:
        return main()
    except RailMonitorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        return 130


def run_node(make: Callable[[], Node], args: list[str] | None = None, flow_control: bool = False) -> int:
    """The main() of every single-node executable; returns the process exit code.

    A node with a ``run(ok)`` method (a pass source) runs it in the foreground while the executor
    spins in the background, and the process ends when it returns; any other node spins until
    SIGINT or SIGTERM, then a node with a ``drain(executor)`` method takes what DDS has already
    delivered (the recorder: nothing published before the signal is lost). ``close()`` runs in
    every case; an error there (a bag that cannot be finished) is exit code 2.
    """
    if isinstance(make, type) and asked_for_help(sys.argv if args is None else args):
        print(help_text(make.EXECUTABLE, sys.modules[make.__module__].__doc__, make.PARAMETERS))
        return 0

    def main() -> int:
        with ros_session(args, flow_control, default_site=getattr(make, "USES_SITE", False)) as stop:
            node = make()
            executor = CoalescingExecutor()
            executor.add_node(node)
            finished = threading.Event()
            # The executor spins in a thread, waking for work or for this guard condition, not on a
            # short timeout: idle, a node costs only its own timers. The main thread waits on the
            # stop event, where signal handlers run at once.
            wake = node.create_guard_condition(lambda: None)
            WAKERS.append(wake.trigger)
            spinner = threading.Thread(target=spin_guarded, args=(executor, lambda: not finished.is_set()),
                                       kwargs={"timeout_sec": IDLE_SPIN_TIMEOUT_S}, daemon=True)

            def stop_spinner() -> None:  # leave no thread inside rcl
                finished.set()
                wake.trigger()
                if spinner.is_alive():
                    spinner.join(timeout=5.0)

            try:
                def ok() -> bool:
                    return not stop.is_set() and rclpy.ok()

                spinner.start()
                job = getattr(node, "run", None)
                if job is not None:
                    job(ok)
                else:
                    while ok() and spinner.is_alive():
                        stop.wait(IDLE_SPIN_TIMEOUT_S)
                    stop_spinner()
                    drain = getattr(node, "drain", None)
                    if drain is not None and rclpy.ok():
                        drain(executor)
            finally:
                stop_spinner()
                WAKERS.remove(wake.trigger)
                shut_down(executor, 1.0)
                try:
                    close = getattr(node, "close", None)
                    if close is not None:
                        close()
                finally:
                    destroy_nodes([node])
        return 0

    return exit_code(main)
