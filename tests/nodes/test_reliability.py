"""Reliability (issue 8): every parameter refused cleanly, a full disk, a recorder killed mid-write,
a 50,000-pass burst, salvage from the command line, and the graph split across two hosts."""

from __future__ import annotations

import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rcl_interfaces.msg import ParameterType
from rclpy.node import Node

from rail_monitor.bagio.passes_bag import write_passes_bag
from rail_monitor.bagio.reader import read_bag_passes, salvage_bag_passes, salvage_mcap
from rail_monitor.core.errors import ConfigError
from rail_monitor.core.simulator_params import simulator_config
from rail_monitor.core.site import site_from_values
from rail_monitor.nodes.alert_manager import AlertManagerNode
from rail_monitor.nodes.corrugation_estimator import CorrugationEstimatorNode
from rail_monitor.nodes.mcap_recorder import McapRecorder
from rail_monitor.nodes.pass_replayer import PassReplayer
from rail_monitor.nodes.pass_simulator import PassSimulator
from rail_monitor.nodes.qos import DIAGNOSTICS_QOS
from rail_monitor.nodes.rolling_noise_predictor import RollingNoisePredictor
from rail_monitor.nodes.squeal_risk_model import SquealRiskNode
from rail_monitor.simulation.simulator import simulate
from rail_monitor.site_file import load_parameter_file

from conftest import SAMPLE, SITE_FILE, TOP, run_cmd, spinning, wait_until


# -- parameters -----------------------------------------------------------------------------------
def _site_file_with(folder: Path, node: str, values: dict) -> Path:
    """The shipped site file with values (dotted names) set in the node's own section."""
    doc = yaml.safe_load(SITE_FILE.read_text())
    section = doc.setdefault(f"/**/{node}", {}).setdefault("ros__parameters", {})
    for key, value in values.items():
        *path, leaf = key.split(".")
        d = section
        for p in path:
            d = d.setdefault(p, {})
        d[leaf] = value
    out = folder / f"{node}.yaml"
    out.write_text(yaml.safe_dump(doc))
    return out


def _bad_values(desc) -> list[tuple[str, object]]:
    """(what, value) out of the parameter's declared range, and of the wrong type."""
    t, out = desc.type, []
    if desc.floating_point_range:
        r = desc.floating_point_range[0]
        if r.from_value > -sys.float_info.max:
            out.append(("below range", r.from_value - max(1.0, abs(r.from_value))))
        if r.to_value < sys.float_info.max:
            out.append(("above range", r.to_value + max(1.0, abs(r.to_value))))
    if desc.integer_range:
        r = desc.integer_range[0]
        if r.from_value > -(2**63):
            out.append(("below range", r.from_value - 1))
        if r.to_value < 2**63 - 1:
            out.append(("above range", r.to_value + 1))
    if desc.additional_constraints.startswith("one of"):
        out.append(("not a choice", "no-such-choice"))
    wrong = {ParameterType.PARAMETER_DOUBLE: "fast", ParameterType.PARAMETER_INTEGER: "many",
             ParameterType.PARAMETER_BOOL: "perhaps", ParameterType.PARAMETER_STRING: 12.5,
             ParameterType.PARAMETER_DOUBLE_ARRAY: "fast", ParameterType.PARAMETER_INTEGER_ARRAY: "many",
             ParameterType.PARAMETER_STRING_ARRAY: 12.5}
    out.append(("wrong type", wrong[t]))
    return out


NODES = {"corrugation_estimator": CorrugationEstimatorNode, "rolling_noise_predictor": RollingNoisePredictor,
         "squeal_risk_model": SquealRiskNode, "alert_manager": AlertManagerNode, "mcap_recorder": McapRecorder,
         "pass_replayer": PassReplayer, "pass_simulator": PassSimulator}


def test_every_bad_parameter_in_a_site_file_is_refused_naming_it_and_its_range(ros_context, tmp_path, tally):
    """Each node is started from the shipped site file plus a second file that sets one of its
    declared parameters out of its declared range or to the wrong type: start-up fails with a
    ConfigError naming the parameter and the allowed values. The parameters come from what the
    node declares, so a new parameter is covered without editing this test."""
    required = {"pass_replayer": {"source": str(SAMPLE)}, "mcap_recorder": {"output": str(tmp_path / "rec")},
                "pass_simulator": {"output": str(tmp_path / "sim")}}
    own = {"use_sim_time", "start_type_description_service"}  # rclpy's own parameters
    tried, seen = 0, set()
    refused_badly = []

    def start(cls, name: str, values: dict):
        site = _site_file_with(tmp_path, name, {**required.get(name, {}), **values})
        return cls(context=ros_context, enable_rosout=False, cli_args=["--ros-args", "--params-file", str(site)])

    for name, cls in NODES.items():
        node = start(cls, name, {})
        names = sorted(set(node._parameters) - own)
        descs = dict(zip(names, node.describe_parameters(names), strict=True))
        node.destroy_node()
        shutil.rmtree(tmp_path / "rec", ignore_errors=True)
        for pname, desc in descs.items():
            if pname in seen:   # site parameters: once
                continue
            seen.add(pname)
            for what, value in _bad_values(desc):
                tried += 1
                try:
                    node = start(cls, name, {pname: value})
                except ConfigError as exc:
                    msg = str(exc)
                    names_range = any(w in msg for w in ("allowed", "one of", "["))
                    if f"'{pname}'" not in msg or "\n" in msg or (what != "wrong type" and not names_range):
                        refused_badly.append((pname, what, value, msg))
                    continue
                except Exception as exc:  # anything but a ConfigError is a failure to refuse cleanly
                    refused_badly.append((pname, what, value, f"{type(exc).__name__}: {exc}"))
                    continue
                node.destroy_node()
                refused_badly.append((pname, what, value, "accepted"))
                shutil.rmtree(tmp_path / "rec", ignore_errors=True)
    assert not refused_badly, "\n".join(map(repr, refused_badly))
    assert len(seen) > 100
    tally("parameters", f"{tried} bad values in a site file ({len(seen)} parameters of 7 nodes: each out of "
          "its declared range and of the wrong type)", "start-up refused with one line naming the parameter "
          "and its allowed values", "-")


# -- the recorder ---------------------------------------------------------------------------------
_STARTED: list[subprocess.Popen] = []


@pytest.fixture(autouse=True)
def _no_process_left():
    """Kill what a failed test left running: a later test on the same DDS domain must not meet it."""
    yield
    while _STARTED:
        p = _STARTED.pop()
        if p.poll() is None:
            p.kill()
            p.wait()


def _recorder(out: Path, log: Path, *extra: str) -> subprocess.Popen:
    with open(log, "w") as err:
        p = subprocess.Popen(["mcap_recorder", "--ros-args", "-r", "__ns:=/site", "-p", f"output:={out}",
                              "-p", "flush_period_s:=0.2", *extra], cwd=TOP, stdout=subprocess.DEVNULL, stderr=err)
    _STARTED.append(p)
    return p


def _replayer(source: Path, *extra: str) -> subprocess.Popen:
    p = subprocess.Popen(["pass_replayer", "--ros-args", "-r", "__ns:=/site", "-p", f"source:={source}",
                          "-p", "wait_for_subscribers:=1", "-p", "progress:=false", *extra],
                         cwd=TOP, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _STARTED.append(p)
    return p


class _RecorderDiagnostics:
    """The recorder's latest /diagnostics status, heard by a node of this process."""

    def __init__(self, ctx) -> None:
        self.node = Node("diagnostics_listener", context=ctx)
        self.status: DiagnosticStatus | None = None
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self._on, DIAGNOSTICS_QOS)

    def _on(self, msg: DiagnosticArray) -> None:
        for st in msg.status:
            if st.name.endswith("/mcap_recorder"):
                self.status = st

    def value(self, key: str) -> str:
        return {kv.key: kv.value for kv in self.status.values}.get(key, "") if self.status else ""


@pytest.fixture()
def small_disk(tmpfs):
    return tmpfs(256 * 1024)


def test_a_full_disk_is_an_error_on_diagnostics_and_what_was_written_stays_readable(
        small_disk, tmp_path, ros_context, sample_passes, tally):
    """The recorder writes uncompressed into a 256 KiB tmpfs while the whole sample (about 1.5 MB
    of TrainPass) is replayed: the disk fills; /diagnostics goes to ERROR naming the cause; the
    replay is not held up; SIGTERM then exits 2 with one line; every whole chunk written before
    the fault is salvaged, byte for byte the first passes of the history."""
    diag = _RecorderDiagnostics(ros_context)
    out = small_disk / "bag"
    rec = _recorder(out, tmp_path / "rec.log", "-p", "compression:=none", "-p", "chunk_size:=8192")
    with spinning(ros_context, diag.node):
        rep = _replayer(SAMPLE)
        _, rep_err = rep.communicate(timeout=300)
        assert rep.returncode == 0, rep_err[-2000:]
        assert wait_until(lambda: diag.status is not None and diag.status.level == DiagnosticStatus.ERROR
                          and int(diag.value("not recorded (write failed)") or 0) > 0, timeout_s=10)
        assert "No space left on device" in diag.status.message
        recorded = int(diag.value("recorded"))
    rec.send_signal(signal.SIGTERM)
    assert rec.wait(timeout=30) == 2
    err = (tmp_path / "rec.log").read_text()
    assert "Traceback" not in err
    assert len([line for line in err.splitlines() if line.startswith("error:")]) == 1
    assert not (out / "metadata.yaml").exists()
    got, _ = salvage_bag_passes(out)
    n = len(sample_passes)
    # The recorder counts a message once its write returns. The message whose write made the writer
    # flush the chunk that filled the disk is inside that chunk: when the chunk itself reached the disk
    # and only its message index did not, the salvage holds that one message more than was counted.
    assert 0 < len(got) <= recorded + 1 and recorded < n
    assert got.equals(sample_passes.take(slice(0, len(got))))   # a prefix, in order, intact
    tally("full disk", f"recorder into a 256 KiB tmpfs, {n} passes replayed", "ERROR on /diagnostics with the "
          f"cause; replay not held up; exit 2 with one line; {len(got)} passes before the fault salvaged intact",
          f"{n - len(got)} not recorded (disk full; {recorded - len(got)} of them in the open chunk)")


def test_sigkill_mid_write_leaves_every_complete_chunk(tmp_path, ros_context, sample_passes, tally):
    """SIGKILL the recorder while a fast replay is still streaming into it: the file (no summary,
    no metadata.yaml) gives back every complete chunk, a prefix of the history, intact."""
    diag = _RecorderDiagnostics(ros_context)
    out = tmp_path / "bag"
    rec = _recorder(out, tmp_path / "rec.log", "-p", "chunk_size:=4096")
    with spinning(ros_context, diag.node):
        rep = _replayer(SAMPLE, "-p", "rate:=777600.0")  # 90 days of history in about 10 s
        try:
            assert wait_until(lambda: int(diag.value("recorded") or 0) >= 2000, timeout_s=120)
            reported = int(diag.value("recorded"))
            rec.send_signal(signal.SIGKILL)
            rec.wait(timeout=30)
        finally:
            rep.kill()
            rep.communicate(timeout=30)
    assert not (out / "metadata.yaml").exists()
    files = sorted(out.glob("*.mcap"))
    got, _ = salvage_bag_passes(out)
    assert got.equals(sample_passes.take(slice(0, len(got))))
    # at most the open chunk (4 KiB, some 30 passes) and what came after the last report is lost
    assert len(got) >= reported - 100, (len(got), reported)
    whole = sum(1 for f in files for _ in salvage_mcap(f))
    tally("recorder SIGKILL", f"killed mid-stream after it reported {reported} messages recorded",
          f"{len(got)} passes ({whole} messages) salvaged from complete chunks, a prefix of the history, intact: "
          f"{100 * len(got) / reported:.1f} % of those reported", "the open chunk")


def test_burst_of_50000_passes_reliable_end_to_end(tmp_path, tally):
    """50,000 passes as fast as the replayer publishes, replayer and recorder in two processes,
    reliable QoS: the recorder's count equals the published count. The recorder is stopped the
    moment the replayer exits: what it has queued is still recorded (this lost 170 before the
    recorder drained its queue on SIGINT)."""
    values = load_parameter_file(SITE_FILE)
    values["simulator.days"] = 200.0
    values["simulator.trains_per_hour"] = [3 * x for x in values["simulator.trains_per_hour"]]
    table = simulate(site_from_values(values), simulator_config(values))
    assert len(table) >= 50_000
    burst = write_passes_bag(table.take(slice(0, 50_000)), tmp_path / "burst", "curve_250")
    rec = _recorder(tmp_path / "rec", tmp_path / "rec.log", "-p", "flush_period_s:=1.0")
    try:
        rep = _replayer(burst, "-p", "publish_clock:=false")
        _, rep_err = rep.communicate(timeout=600)
        assert rep.returncode == 0, rep_err[-2000:]
        published = int(re.search(r"published (\d+) of (\d+) passes", rep_err).group(1))
    finally:
        rec.send_signal(signal.SIGINT)
        assert rec.wait(timeout=60) == 0
    recorded = yaml.safe_load((tmp_path / "rec" / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    counts = {t["topic_metadata"]["name"]: t["message_count"] for t in recorded["topics_with_message_count"]}
    assert published == 50_000
    assert counts["/site/train_pass"] == published
    assert read_bag_passes(tmp_path / "rec").equals(read_bag_passes(burst))
    tally("load", "a burst of 50,000 passes, replayer to recorder in two processes, as fast as published, "
          "reliable", "the recorder holds all 50,000, equal to the source", 0)


# -- salvage from the command line ----------------------------------------------------------------
def test_salvage_option_reads_the_complete_chunks_of_a_cut_bag(tmp_path, sample_passes, tally):
    bag = write_passes_bag(sample_passes, tmp_path / "small_chunks", "curve_250", chunk_size=16384)
    whole = (bag / "small_chunks_0.mcap").read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole[: int(len(whole) * 0.6)])
    r = run_cmd("rail-monitor", "info", str(cut))
    assert r.returncode != 0 and "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1
    expected = sum(1 for _ in salvage_mcap(cut))
    assert 0 < expected < len(sample_passes)
    r = run_cmd("rail-monitor", "info", "--salvage", str(cut))
    assert r.returncode == 0, r.stderr
    assert f"salvaged {expected} messages ({expected} TrainPass) from the complete chunks of 1 MCAP file(s)" \
        in r.stdout
    assert f"passes:    {expected} " in r.stdout
    assert salvage_bag_passes(cut)[0].equals(sample_passes.take(slice(0, expected)))
    r = run_cmd("rail-monitor", "batch", "--salvage", str(cut), "--output", str(tmp_path / "b"), "--no-report",
                timeout=300)
    assert r.returncode == 0, r.stderr
    assert f"batch: {expected} passes" in r.stdout
    tally("salvage", f"the sample as an MCAP of 16 KiB chunks, cut at 60 %: {expected} of {len(sample_passes)} "
          "passes in complete chunks",
          "plain read: one-line error, non-zero exit; --salvage: all of them recovered and counted, "
          "batch runs on them",
          f"{len(sample_passes) - expected} (the cut-off part)")
