"""The executables as the ROS 2 tools use them (issue 23): --help, parameters changed on a running
node, the logger-level service, the start-up line, and the launch file's process list."""

from __future__ import annotations

import ast

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient

from rail_monitor.nodes.alert_manager import AlertManagerNode
from rail_monitor.nodes.layout import PROCESSES, SOURCE

from conftest import TOP, run_cmd, spinning, wait_until

EXECUTABLES = ("pass_replayer", "pass_simulator", "mcap_recorder", "squeal_risk_model", "corrugation_estimator",
               "rolling_noise_predictor", "alert_manager", "wayside_monitor", "noise_station", "site_engine")


@pytest.mark.parametrize("exe", EXECUTABLES)
def test_help_lists_the_parameters_and_starts_nothing(exe):
    before = sorted(TOP.glob("rail_monitor_*"))
    r = run_cmd(exe, "--help", timeout=60)
    assert r.returncode == 0, r.stderr[-1500:]
    assert sorted(TOP.glob("rail_monitor_*")) == before  # the recorder wrote no bag
    assert r.stdout.startswith(f"usage: {exe} ") and "\nparameters:\n" in r.stdout
    assert "[INFO]" not in r.stderr and "started:" not in r.stderr  # no node was made
    # every parameter line names a type, and numbers their range and default
    lines = [line for line in r.stdout.splitlines() if line.startswith("  ") and not line.startswith("      ")]
    assert len(lines) >= 10 and all("; default " in line for line in lines)
    if exe == "mcap_recorder":
        assert "  max_total_bytes (int, [0, 1.1259e+15]; default 0)" in r.stdout
    if exe == "wayside_monitor":
        names = [line.split()[0] for line in lines]
        assert len(names) == len(set(names)) and "alerts.noise_limit_dba" in names and "source" in names


def test_no_bag_is_written_by_recorder_help(tmp_path):
    r = run_cmd("mcap_recorder", "-h", "--ros-args", "-p", f"output:={tmp_path / 'bag'}", timeout=60)
    assert r.returncode == 0 and not (tmp_path / "bag").exists()


def _set(client: AsyncParameterClient, **values) -> list:
    fut = client.set_parameters([Parameter(k, value=v) for k, v in values.items()])
    assert wait_until(fut.done, 10)
    return fut.result().results


def test_alert_limits_are_tuned_on_a_running_node_and_bad_values_refused(ros_context, site_values):
    params = [Parameter(k, value=v) for k, v in site_values.items() if not k.startswith("simulator.")]
    node = AlertManagerNode(context=ros_context, namespace="/curve_250", parameter_overrides=params)
    probe = Node("operator", context=ros_context)
    client = AsyncParameterClient(probe, "/curve_250/alert_manager")
    with spinning(ros_context, node, probe):
        assert client.wait_for_services(10)
        (ok,) = _set(client, **{"alerts.noise_limit_dba": 70.0})
        assert ok.successful and node.alerts.cfg.noise_limit_dba == 70.0
        (window,) = _set(client, **{"alerts.squeal_window_passes": 50})
        assert window.successful and node.alerts._squeal.flags.maxlen == 50
        # no hysteresis left: refused with the reason, nothing changed
        (bad,) = _set(client, **{"alerts.noise_clear_count": 5})
        assert not bad.successful and "needs hysteresis" in bad.reason and node.alerts.cfg.noise_clear_count == 0
        (out_of_range,) = _set(client, **{"alerts.squeal_raise_share": 1.5})
        assert not out_of_range.successful and node.alerts.cfg.squeal_raise_share == 0.2
        (quieter,) = _set(client, log_throttle_s=60.0)
        assert quieter.successful and node.log_throttle_s == 60.0
        (read_only,) = _set(client, **{"max_batch": 5})  # not a runtime parameter
        assert not read_only.successful and node.max_batch == 200
        # the logger-level service of every node
        names = {n for n, _ in probe.get_service_names_and_types()}
        assert "/curve_250/alert_manager/set_logger_levels" in names
    probe.destroy_node()
    node.destroy_node()


def test_a_node_states_its_topics_and_key_parameters_at_start():
    r = run_cmd("timeout", "-s", "INT", "3", "squeal_risk_model", "--ros-args", "-r", "__ns:=/curve_250",
                "--params-file", str(TOP / "src/rail_monitor/config/curve_250.yaml"), timeout=60)
    line = next(x for x in r.stderr.splitlines() if "started:" in x)
    subscribed, published = (line.split(f"{verb} ", 1)[1].split(";", 1)[0].split(", ")
                             for verb in ("subscribes", "publishes"))
    assert {"/curve_250/train_pass", "/curve_250/noise/measured"} <= set(subscribed)  # the squeal fit's input
    assert {"/curve_250/noise/squeal", "/curve_250/noise/squeal_calibration"} <= set(published)
    assert "site=curve_250" in line and "classes=emu/dmu/freight" in line and "k3=" in line


def test_the_launch_file_starts_the_tested_layout():
    # The launch file builds its nodes from rail_monitor.nodes.layout, the list the separate-process
    # tests run; it shuts the launch down when the source exits and types the rate argument.
    text = (TOP / "src/rail_monitor/launch/wayside.launch.py").read_text()
    tree = ast.parse(text)
    imported = {a.name for n in ast.walk(tree)
                if isinstance(n, ast.ImportFrom) and n.module == "rail_monitor.nodes.layout" for a in n.names}
    assert {"PROCESSES", "SOURCE", "FLOAT_ARGUMENTS"} <= imported
    assert "OnProcessExit" in text and "Shutdown" in text and "value_type=float" in text
    assert [p.executable for p in PROCESSES][-1] == SOURCE
    # The station hears a site's own recordings: started beside the launch where a site has them.
    # site_engine is the four model nodes in one (wayside_monitor hosts it).
    assert {p.executable for p in PROCESSES} == set(EXECUTABLES) - {"pass_simulator", "wayside_monitor",
                                                                    "noise_station", "site_engine"}
