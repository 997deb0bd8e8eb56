"""rail-monitor predict squeal as a user runs it (rail_monitor.cli.predict_squeal), in-process."""

from __future__ import annotations

import json

import pytest

from rail_monitor.cli import main


def test_predict_squeal_reproduces_the_rig(tmp_path, capsys):
    """The UQ paper's rig: A w = 0.33 m/s at Vc = 0.39 m/s (3 %), a sweep with both regimes, a plot."""
    png = tmp_path / "sweep.png"
    assert main(["predict", "squeal", "--rig", "--crabbing", "0.39", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["rows"][0]
    assert row["velocity_amplitude_mps"] == pytest.approx(0.33, rel=0.03)
    assert main(["predict", "squeal", "--rig", "--sweep", "0.05", "0.5", "10", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    assert "stable" in out and "limit cycle" in out
    assert main(["predict", "squeal", "--rig", "--load", "2000"]) == 2
    err = capsys.readouterr().err
    assert "error" in err and "Traceback" not in err and err.count("\n") == 1


def test_a_site_case_names_its_class_and_friction(capsys):
    assert main(["predict", "squeal", "--vehicle-class", "freight", "--friction", "wet", "--aoa-mrad", "12"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("# site curve_250, class freight, wet: V0 14 m/s, W 100000 N") and len(out) == 3
