"""Executables as separate processes: ros2-run resolution, DDS between processes, signals."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import yaml
from ament_index_python.packages import get_package_prefix
from rosbags.highlevel import AnyReader

from rail_monitor.bagio.reader import read_bag_passes, salvage_mcap

from conftest import SAMPLE, TOP, executable, run_cmd, wait_until

FIVE_DAYS = str(5 * 86400.0)


def _expected_slice() -> int:
    t = read_bag_passes(SAMPLE)
    return int((t.stamp_ns <= t.stamp_ns[0] + int(float(FIVE_DAYS) * 1e9)).sum())


def _start_recorder(out: Path, *extra: str) -> subprocess.Popen:
    p = subprocess.Popen([executable("mcap_recorder"), "--ros-args", "-p", f"output:={out}", "-r", "__ns:=/site",
                          "-p", "flush_period_s:=0.2", *extra],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=TOP)
    return p


def _replay(*extra: str) -> subprocess.CompletedProcess:
    return run_cmd(executable("pass_replayer"), "--ros-args", "-r", "__ns:=/site", "-p", f"source:={SAMPLE}",
                   "-p", f"end_offset_s:={FIVE_DAYS}", "-p", "wait_for_subscribers:=1", "-p", "progress:=false",
                   *extra, timeout=120)


def test_ament_index_resolves_every_executable():
    for name in ("pass_replayer", "pass_simulator", "mcap_recorder", "wayside_monitor", "rail-monitor"):
        executable(name)
    r = run_cmd(executable("rail-monitor"), "replay", "--help")
    assert r.returncode == 0
    # --help shows each node parameter with its unit, range and default
    assert "default: 0.0 [rate]" in r.stdout and "[s]" in r.stdout and "[0, 1e+09]" in r.stdout


def test_two_processes_over_dds_lose_nothing_and_sigint_finalises(tmp_path: Path, tally):
    rec = _start_recorder(tmp_path / "two")
    try:
        r = _replay()
        assert r.returncode == 0, r.stderr
        n = _expected_slice()
        time.sleep(1.0)  # let the last acknowledged samples be taken
    finally:
        rec.send_signal(signal.SIGINT)
        out, _ = rec.communicate(timeout=30)
    assert rec.returncode == 0, out
    with AnyReader([tmp_path / "two"]) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert counts["/site/train_pass"] == n
    assert read_bag_passes(tmp_path / "two").equals(read_bag_passes(SAMPLE).take(slice(0, n)))
    tally("recorder SIGINT", f"replayer to recorder over DDS, {n} passes, then SIGINT",
          "exit 0, indexed bag with metadata, equal to the source", 0)


def test_sigterm_finalises_an_indexed_bag(tmp_path: Path, tally):
    rec = _start_recorder(tmp_path / "term")
    try:
        assert _replay().returncode == 0
        time.sleep(1.0)
    finally:
        rec.send_signal(signal.SIGTERM)
        out, _ = rec.communicate(timeout=30)
    assert rec.returncode == 0, out
    meta = yaml.safe_load((tmp_path / "term" / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    topics = {t["topic_metadata"]["name"]: t["message_count"] for t in meta["topics_with_message_count"]}
    assert topics["/site/train_pass"] == _expected_slice()
    tally("recorder SIGTERM", f"{_expected_slice()} passes, then SIGTERM", "exit 0, indexed bag with metadata", 0)


def test_sigkill_leaves_every_flushed_chunk_readable(tmp_path: Path):
    rec = _start_recorder(tmp_path / "kill", "-p", "chunk_size:=4096")
    try:
        assert _replay().returncode == 0
        time.sleep(1.5)  # > flush_period_s: every chunk is closed and written
    finally:
        rec.send_signal(signal.SIGKILL)
        rec.communicate(timeout=30)
    assert not (tmp_path / "kill" / "metadata.yaml").exists()  # killed: never finalised
    files = sorted((tmp_path / "kill").glob("*.mcap"))
    salvaged = [m for f in files for m in salvage_mcap(f) if m.topic == "/site/train_pass"]
    assert len(salvaged) == _expected_slice()


def test_wayside_monitor_runs_the_graph_on_a_slice(tmp_path: Path):
    r = run_cmd("rail-monitor", "monitor", str(SAMPLE), "--output", str(tmp_path / "wm"),
                "--end-offset-s", FIVE_DAYS, "--no-progress", timeout=180)
    assert r.returncode == 0, r.stderr
    n = _expected_slice()
    assert f"{n} passes through the graph" in r.stdout
    with AnyReader([tmp_path / "wm"]) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert counts["/curve_250/train_pass"] == n


def test_replayer_with_unusable_csv_exits_nonzero_naming_the_line(tmp_path: Path):
    bad = tmp_path / "bad.csv"
    bad.write_text("time_utc,train_id,vehicle_class,vehicle_count,speed_mps,angle_of_attack_rad,friction_state\n"
                   "2026-09-01T05:00:00Z,T1,emu,3,nineteen,0.005,dry\n", encoding="utf-8")
    r = run_cmd(executable("pass_replayer"), "--ros-args", "-p", f"source:={bad}", timeout=60)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "line 2: column 'speed_mps'" in r.stderr


def test_recorded_log_times_are_receive_times_on_pass_time_never_1970(tmp_path: Path):
    # As rosbag2 records: log time = the recorder's clock at receipt, here sim time (/clock from
    # the replayer). Every message of every topic (/diagnostics and the first standing alerts too)
    # lies within the replayed pass times, so a timeline (Foxglove's) spans the history, not 57 years.
    r = run_cmd("rail-monitor", "monitor", str(SAMPLE), "--output", str(tmp_path / "lt"),
                "--end-offset-s", FIVE_DAYS, "--no-progress", timeout=180)
    assert r.returncode == 0, r.stderr
    passes = read_bag_passes(SAMPLE)
    first, last = int(passes.stamp_ns[0]), int(passes.stamp_ns[0]) + int(float(FIVE_DAYS) * 1e9)
    with AnyReader([tmp_path / "lt"]) as reader:
        times = {c.topic: [t for _, t, _ in reader.messages(connections=[c])] for c in reader.connections}
    assert times["/curve_250/train_pass"] and times["/curve_250/alerts/standing"]
    for topic, ts in times.items():  # a topic may have no message yet (/diagnostics ticks once a second)
        assert not ts or (first <= min(ts) and max(ts) <= last), (topic, min(ts), max(ts))
    pass_times = times["/curve_250/train_pass"]
    assert pass_times == sorted(pass_times)  # receipt order is pass order


def test_launch_file_and_site_config_are_installed():
    import ast

    share = Path(get_package_prefix("rail_monitor")) / "share" / "rail_monitor"
    tree = ast.parse((share / "launch" / "wayside.launch.py").read_text())
    assert any(isinstance(n, ast.FunctionDef) and n.name == "generate_launch_description" for n in tree.body)
    assert (share / "config" / "curve_250.yaml").is_file()
    assert (share / "config" / "fastdds_flow_control.xml").is_file()


def test_corrugation_state_bursts_reach_another_process_whole_over_udp(tally):
    """Every corrugation state reaches a subscriber that needs them all (noise predictor, alert
    manager, recorder), when they go out in the estimator's bursts between processes over UDP
    only. Found with a depth-1 writer: a reliable KEEP_LAST writer overwrites samples not yet
    delivered, and 273-590 of 3000 states were lost in 6 runs (one lost state changed a noise prediction)."""
    n = 3000
    env = {**os.environ, "FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"}  # shared memory would hide the loss
    script = str(Path(__file__).with_name("state_burst.py"))
    sub = subprocess.Popen([sys.executable, script, "sub", str(n)], env=env, cwd=TOP, text=True,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        pub = run_cmd(sys.executable, script, "pub", str(n), env=env, timeout=90)
        out, err = sub.communicate(timeout=60)
    finally:
        sub.kill()
    assert pub.returncode == 0, pub.stderr[-2000:]
    assert sub.returncode == 0, err[-2000:]
    received, distinct = map(int, out.split())
    assert received == distinct == n
    tally("state bursts over UDP", f"{n} corrugation states in bursts of 200, publisher and subscriber in two "
          "processes, UDP only", "every state received, once", n - received)


def test_a_signal_mid_replay_stops_the_source_and_the_graph_cleanly(tmp_path):
    """SIGINT to pass_replayer and SIGTERM to wayside_monitor in the middle of a replay: each stops
    within 5 s, exit 0, no traceback; the graph still finishes its bag with what it took."""
    site = TOP / "src" / "rail_monitor" / "config" / "curve_250.yaml"
    cases = [
        (["pass_replayer", "--ros-args", "-p", f"source:={SAMPLE}", "-p", "rate:=100000.0", "-p", "progress:=false"],
         signal.SIGINT, None),
        (["wayside_monitor", "--ros-args", "--params-file", str(site), "-p", f"source:={SAMPLE}", "-p",
          f"output:={tmp_path / 'bag'}", "-p", "use_sim_time:=true", "-p", "progress:=false", "-p",
          "rate:=100000.0"], signal.SIGTERM,
         tmp_path / "bag"),
    ]
    for argv, sig, bag in cases:
        p = subprocess.Popen([executable(argv[0]), *argv[1:]], cwd=TOP, text=True, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE)
        lines: list[str] = []
        reader = threading.Thread(target=lines.extend, args=(p.stderr,), daemon=True)
        reader.start()
        # Past the set-up (its site tables may be built cold: seconds), then 1 s into the replay,
        # which at 1e5 x pass time takes 77 s.
        assert wait_until(lambda seen=lines: any("[pass_replayer]: started:" in line for line in seen), 60), lines
        time.sleep(1.0)
        assert p.poll() is None, f"{argv[0]} ended before the signal"
        p.send_signal(sig)
        t0 = time.monotonic()
        p.wait(timeout=30)
        reader.join(timeout=10)
        err = "".join(lines)
        assert time.monotonic() - t0 < 5.0 and p.returncode == 0 and "Traceback" not in err, (argv[0], err[-1500:])
        if bag is not None:
            assert 0 < len(read_bag_passes(bag)) < 8638


def test_a_model_node_started_bare_reads_the_shipped_site():
    """No --params-file: a model node says so and reads the shipped site file (all three classes),
    as the command line does; before, it knew only the default 'emu' and rejected every other
    pass (issue 24: 1,653 DMU and freight passes)."""
    p = subprocess.Popen([executable("squeal_risk_model"), "--ros-args", "-r", "__ns:=/bare"], stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, cwd=TOP)
    lines = []
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not any("started:" in line for line in lines):
            lines.append(p.stdout.readline())
    finally:
        p.send_signal(signal.SIGINT)
        p.wait(timeout=30)
    text = "".join(lines)
    assert "curve_250.yaml (shipped; no --params-file given)" in text, text
    assert "classes=emu/dmu/freight" in text, text
    assert p.returncode == 0


def test_the_executables_executor_answers_at_once_when_idle_and_takes_a_burst_in_one_go(ros_context):
    # CoalescingExecutor (every single-node executable): a first message after idling is handled
    # at once; after a wake-up with work it pauses before waiting again, so messages arriving in
    # that pause reach one callback together (take_queued) instead of one wake-up each.
    from rclpy.node import Node
    from std_msgs.msg import String

    from rail_monitor.nodes.base import subscribe_batched
    from rail_monitor.nodes.process import CoalescingExecutor

    node = Node("coalescing_probe", context=ros_context)
    batches: list[list[str]] = []
    subscribe_batched(node, String, "burst", lambda msgs: batches.append([m.data for m in msgs]), 10, 10)
    pub = node.create_publisher(String, "burst", 10)
    ex = CoalescingExecutor(coalesce_s=0.3, context=ros_context)
    ex.add_node(node)
    try:
        assert wait_until(lambda: pub.get_subscription_count() == 1)
        pub.publish(String(data="a"))
        t = time.monotonic()
        ex.spin_once(timeout_sec=2.0)
        assert batches == [["a"]] and time.monotonic() - t < 0.3
        threading.Timer(0.05, lambda: [pub.publish(String(data=x)) for x in "bc"]).start()
        t = time.monotonic()
        ex.spin_once(timeout_sec=2.0)
        assert batches == [["a"], ["b", "c"]] and time.monotonic() - t >= 0.3
    finally:
        ex.shutdown()
        node.destroy_node()


STUCK_TEARDOWN = """
import sys, time
from pathlib import Path
from rclpy.node import Node
from rail_monitor.nodes import process

class Stuck(Node):
    def __init__(self):
        super().__init__("teardown_probe")
        print("started", flush=True)

    def close(self):
        Path(sys.argv[1]).write_text("closed")

    def destroy_node(self):  # as rcl's participant deletion that never returned
        time.sleep(600)

process.TEARDOWN_HANG_S = 1.0
sys.exit(process.run_node(Stuck, ["teardown_probe"]))
"""


def test_a_teardown_that_hangs_after_the_outputs_are_closed_ends_the_process(tmp_path):
    """A node whose destroy_node never returns (seen once in rcl under load, after SIGINT): the
    process still closes its outputs, then ends within the teardown deadline with exit code 1 and
    every thread's stack on stderr, instead of running until a supervisor kills it."""
    marker = tmp_path / "closed"
    p = subprocess.Popen([sys.executable, "-c", STUCK_TEARDOWN, str(marker)], cwd=TOP, text=True,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        assert p.stdout.readline().strip() == "started"
        p.send_signal(signal.SIGINT)
        t0 = time.monotonic()
        _, err = p.communicate(timeout=60)
        took = time.monotonic() - t0
    finally:
        p.kill()
    assert marker.read_text() == "closed"
    assert p.returncode == 1 and took < 15.0, (p.returncode, took, err[-1500:])
    assert "Timeout" in err and "in destroy_node" in err, err[-1500:]


def test_a_node_process_starts_without_the_scipy_packages_only_later_work_needs():
    """Start-up to a first output (docs/benchmarks.md): importing scipy.signal and scipy.stats cost
    a node 0.9 s of CPU before it subscribed; only the station's time weighting and the speed
    advice need them, so the graph's modules leave them to be imported on first use."""
    code = ("import sys, rail_monitor.nodes.wayside_monitor, rail_monitor.nodes.site_engine; "
            "print(' '.join(m for m in ('scipy.signal', 'scipy.stats', 'scipy.optimize') if m in sys.modules))")
    out = run_cmd(sys.executable, "-c", code, cwd=TOP, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", f"imported at start-up: {out.stdout.strip()}"
