"""Shared node glue (rail_monitor.nodes.base): the strict parameter-name check, the failure isolation
of a batch of passes, and the one main() of the executables."""

from __future__ import annotations

import pytest
from rclpy.parameter import Parameter

from rail_monitor.core.errors import ConfigError
from rail_monitor.nodes.base import isolate_failures
from rail_monitor.nodes.squeal_risk_model import SquealRiskNode

from conftest import run_cmd


def test_an_unknown_parameter_name_is_refused_with_the_nearest_known_one(ros_context, site_values):
    params = [Parameter(k, value=v) for k, v in site_values.items()]
    want = r"unknown parameter 'squeal\.modal_mas'; did you mean 'squeal\.modal_mass_kg'"
    with pytest.raises(ConfigError, match=want):
        SquealRiskNode(context=ros_context, parameter_overrides=[*params, Parameter("squeal.modal_mas", value=1.0)])
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


@pytest.mark.parametrize("args", [["--params-file", "/no/such/site.yaml"], ["-p", "rate:="]])
def test_a_params_file_or_value_rcl_refuses_is_one_line_and_exit_2(args):
    r = run_cmd("pass_replayer", "--ros-args", *args, "-p", "source:=bags/sample", timeout=60)
    assert r.returncode == 2, r.stderr[-2000:]
    lines = [line for line in r.stderr.splitlines() if line.strip() and not line.startswith("[")]
    assert len(lines) == 1 and lines[0].startswith("error: cannot start:") and "Traceback" not in r.stderr


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
