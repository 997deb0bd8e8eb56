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
