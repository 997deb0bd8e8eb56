"""Shared node glue (rail_monitor.nodes.base): the strict parameter-name check, the failure isolation
of a batch of passes, and the one main() of the executables."""

from __future__ import annotations

import time

import numpy as np
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter

from rail_monitor.core.errors import ConfigError
from rail_monitor.nodes.base import Diagnostics, isolate_failures
from rail_monitor.nodes.squeal_risk_model import SquealRiskNode

from conftest import run_cmd


def test_an_unknown_parameter_name_is_refused_with_the_nearest_known_one(ros_context, site_values):
    params = [Parameter(k, value=v) for k, v in site_values.items()]
    want = r"unknown parameter 'squeal\.receiver_distanc'; did you mean 'squeal\.receiver_distance_m'"
    with pytest.raises(ConfigError, match=want):
        SquealRiskNode(context=ros_context,
                       parameter_overrides=[*params, Parameter("squeal.receiver_distanc", value=1.0)])
    node = SquealRiskNode(context=ros_context, parameter_overrides=params)  # the site file alone is fine
    node.destroy_node()


def test_an_executable_given_a_misspelt_parameter_exits_2_with_one_line():
    r = run_cmd("pass_replayer", "--ros-args", "-p", "source:=bags/sample", "-p", "end_ofset_s:=10.0", timeout=60)
    assert r.returncode == 2, r.stderr[-2000:]
    err = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(err) == 1 and "did you mean 'end_offset_s'" in err[0] and "Traceback" not in r.stderr


def test_isolate_failures_runs_the_rest_when_one_item_fails():
    done, failed = [], []

    def call(rows: slice) -> None:
        items = list(range(5))[rows]
        if 3 in items:
            raise ValueError("bad item")
        done.extend(items)

    isolate_failures(5, call, lambda i, exc: failed.append((i, str(exc))))
    assert done == [0, 1, 2, 4] and failed == [(3, "bad item")]
    done.clear()
    isolate_failures(2, call, lambda i, exc: failed.append(i))
    assert done == [0, 1]


@pytest.mark.parametrize(("args", "start"), [(["--params-file", "/no/such/site.yaml"], "error: /no/such/site.yaml: "),
                                             (["-p", "rate:="], "error: cannot start:")])
def test_a_params_file_or_value_rcl_refuses_is_one_line_and_exit_2(args, start):
    r = run_cmd("pass_replayer", "--ros-args", *args, "-p", "source:=bags/sample", timeout=60)
    assert r.returncode == 2, r.stderr[-2000:]
    lines = [line for line in r.stderr.splitlines() if line.strip() and not line.startswith("[")]
    assert len(lines) == 1 and lines[0].startswith(start) and "Traceback" not in r.stderr


@pytest.mark.parametrize(("section", "value", "says"), [
    ("/**", '"fast"', "parameter 'rate' must be float, got str 'fast'"),
    ("/**/pass_replayer", "10", "parameter 'rate' must be a double: write 10 with a decimal point"),
    ("/**", "-1.0", "parameter 'rate' = -1.0 is outside its range"),
    ("/**", "{max_ahead_of_stream_s: true}", "parameter 'stamps.max_ahead_of_stream_s' must be float")])
def test_a_later_params_file_of_the_wrong_type_is_refused_like_the_first(tmp_path, section, value, says):
    # rcl keeps the first file's value when a later one's type differs, without a word: each
    # file is checked on its own, and the later one is refused naming it and the parameter.
    first = tmp_path / "first.yaml"
    first.write_text("/**:\n  ros__parameters:\n    rate: 5.0\n")
    later = tmp_path / "later.yaml"
    name = "stamps" if "stamps" in says else "rate"
    later.write_text(f"{section}:\n  ros__parameters:\n    {name}: {value}\n")
    r = run_cmd("pass_replayer", "--ros-args", "--params-file", str(first), "--params-file", str(later),
                "-p", "source:=bags/sample", timeout=60)
    assert r.returncode == 2, r.stderr[-2000:]
    lines = [line for line in r.stderr.splitlines() if line.strip() and not line.startswith("[")]
    assert len(lines) == 1 and str(later) in lines[0] and says in lines[0], lines


def test_a_recorder_output_that_is_a_file_or_a_dangling_link_is_one_line(tmp_path):
    import os

    a_file = tmp_path / "file"
    a_file.write_text("mine")
    link = tmp_path / "link"
    os.symlink(tmp_path / "nowhere", link)
    for out in (a_file, link):
        r = run_cmd("mcap_recorder", "--ros-args", "-p", f"output:={out}", timeout=60)
        assert r.returncode == 2 and "not a folder" in r.stderr and "Traceback" not in r.stderr, r.stderr[-1500:]
    assert a_file.read_text() == "mine"


def test_a_recorder_budget_that_cannot_hold_is_one_line_at_start(tmp_path):
    r = run_cmd("mcap_recorder", "--ros-args", "-p", f"output:={tmp_path / 'bag'}", "-p", "max_total_bytes:=1000000",
                timeout=60)
    assert r.returncode == 2 and "needs files split by size" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "bag").exists()


def test_diagnostics_of_nodes_started_apart_fall_due_together(ros_context):
    # Statuses are due at whole multiples of the period on the steady clock, which processes share:
    # nodes started 0.3 s apart publish in the same wake-up (an idle process's CPU is its wake-ups).
    period, beats, nodes = 0.5, {}, []
    executor = SingleThreadedExecutor(context=ros_context)
    for name in ("diag_early", "diag_late"):
        node = rclpy.create_node(name, context=ros_context)
        beats[name] = []
        Diagnostics(node, lambda b=beats[name]: b.append(time.monotonic()) or {}, period_s=period)
        executor.add_node(node)
        nodes.append(node)
        time.sleep(0.3)
    end = time.monotonic() + 2.3
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.05)
    executor.shutdown()
    for node in nodes:
        node.destroy_node()
    assert all(len(b) >= 3 for b in beats.values()), beats
    for b in beats.values():  # the first beat of the early node waited for the executor to spin
        phase = np.array(b[1:]) % period
        assert np.all(np.minimum(phase, period - phase) < 0.05), phase  # executor latency allowed
