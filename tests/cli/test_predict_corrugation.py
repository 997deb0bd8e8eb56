"""rail-monitor predict corrugation as a user runs it (rail_monitor.cli.predict_corrugation), in-process."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rail_monitor.cli import main
from rail_monitor.core.passes import FRICTION_DRY
from rail_monitor.corrugation import advice
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator


def test_predict_corrugation_json_equals_the_library_and_plots(tmp_path, site, capsys):
    png = tmp_path / "growth.png"
    assert main(["predict", "corrugation", "--speed-mean", "17", "--speed-cv", "0.05", "--passes-per-day", "100",
                 "--advise", "--json", "--plot-growth", str(png)]) == 0
    doc = json.loads(capsys.readouterr().out)
    est = CorrugationEstimator(site, corrugation_config({}))
    v = 17 * (1 + 0.05 * np.linspace(-3, 3, 121))
    want = advice.evaluate(est, v, np.exp(-0.5 * ((v - 17) / 0.85) ** 2), FRICTION_DRY, 100.0)
    assert doc["peak_growth"] == pytest.approx(want.peak_growth, rel=1e-12)
    assert doc["days_to_threshold"] == pytest.approx(want.days_to_threshold, rel=1e-9)
    assert len(doc["bands"]) == len(est.bands) and doc["advice"]["grinding_interval_factor"] > 1.0
    assert png.stat().st_size > 10_000


def test_an_unreadable_history_is_one_line_and_exit_2(tmp_path, capsys):
    bad = tmp_path / "broken.mcap"
    bad.write_bytes(b"\x89MCAP0\r\n garbage")
    assert main(["predict", "corrugation", "--history", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and str(bad) in err


def test_a_table_without_json(capsys):
    assert main(["predict", "corrugation", "--speeds", "15", "17", "19", "--weights", "1", "2", "1"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("# site curve_250, post-grinding rail, dry") and out[-1].startswith("peak g ")
