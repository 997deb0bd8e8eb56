"""What the command line prints as JSON: strict JSON, non-finite numbers as null (issue 24)."""

from __future__ import annotations

import json
import math

import numpy as np

from rail_monitor.cli import main
from rail_monitor.cli.common import jsonable


def _strict(text: str):
    """json.loads refusing NaN and Infinity, as jq and JavaScript's JSON.parse do."""
    def refuse(name: str):
        raise ValueError(f"not JSON: {name}")

    return json.loads(text, parse_constant=refuse)


def test_non_finite_numbers_and_numpy_values_become_json():
    data = {"never": math.inf, "none": np.float64("nan"), "n": np.int64(3), "a": np.array([1.0, np.inf]),
            "t": (np.bool_(True), -math.inf), 4: "key"}
    assert jsonable(data) == {"never": None, "none": None, "n": 3, "a": [1.0, None], "t": [True, None], "4": "key"}
    assert _strict(json.dumps(jsonable(data), allow_nan=False))["a"] == [1.0, None]


def test_predict_corrugation_json_parses_as_strict_json(capsys):
    # A track whose bands never reach their threshold at this traffic printed Infinity before.
    assert main(["predict", "corrugation", "--json"]) == 0
    out = capsys.readouterr().out
    data = _strict(out)
    assert "Infinity" not in out and "NaN" not in out and isinstance(data, dict) and data


def test_a_users_parameter_beats_the_site_files_node_section(tmp_path):
    """rcl takes a node's own params-file section over any -p: the command line's overrides file
    makes `-p checkpoint_path:=...` reach corrugation_estimator, whose section in the shipped site
    file sets checkpoint_path to '' (issue 24: no checkpoint was written)."""
    import argparse
    import subprocess
    import sys

    from rail_monitor.cli.common import ros_args, site_file

    ns = argparse.Namespace(namespace="curve_250", ros_extra=["--ros-args", "-p", f"checkpoint_path:={tmp_path}/s.npz",
                                                              "-p", "state_wait_s:=2.5"])
    args = ros_args(ns, site_file(None), {"source": "x.csv"})
    probe = ("import sys, rclpy; from rclpy.node import Node; rclpy.init(args=sys.argv); "
             "n = Node('corrugation_estimator'); "
             "print(n.declare_parameter('checkpoint_path', '').value, n.declare_parameter('state_wait_s', 0.0).value, "
             "n.declare_parameter('source', '').value, n.get_namespace())")
    r = subprocess.run([sys.executable, "-c", probe, *args[1:]], capture_output=True, text=True, timeout=60)
    assert r.stdout.split() == [f"{tmp_path}/s.npz", "2.5", "x.csv", "/curve_250"], r.stderr
