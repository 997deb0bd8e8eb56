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
    assert out[0].startswith("# site curve_250, class freight, wet: V0 14 m/s, W 100000 N") and len(out) == 4


def test_a_site_case_gives_the_level_and_risk_the_squeal_node_gives(capsys):
    """predict squeal for a site: dB(A), risk and regime equal squeal.predict.predict (what the
    squeal_risk_model node and batch mode run) for the same pass, exactly: one computation."""
    import numpy as np

    from rail_monitor.alerts.config import RISK_NAMES
    from rail_monitor.cli.common import site_values
    from rail_monitor.core.passes import FRICTION_BY_NAME, PassTable
    from rail_monitor.core.site import site_from_values
    from rail_monitor.models.squeal import REGIME_NAMES
    from rail_monitor.squeal.config import squeal_config
    from rail_monitor.squeal.predict import predict

    assert main(["predict", "squeal", "--vehicle-class", "emu", "--speed", "18", "--aoa-mrad", "13", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["rows"][0]
    values = site_values(None)
    site = site_from_values(values)
    emu = site.vehicle("emu")
    table = PassTable(stamp_ns=[1], train_id=["t"], vehicle_class=["emu"], vehicle_count=[3], axle_count=[12],
                      speed_mps=[18.0], angle_of_attack_rad=[np.arcsin(row["crabbing_velocity_mps"] / 18.0)],
                      wheel_load_n=[emu.wheel_load_n], friction_state=[FRICTION_BY_NAME["dry"]],
                      train_length_m=[60.0])
    node = predict(squeal_config(values), site, table)
    assert row["level_dba"] == pytest.approx(float(node["level_dba"][0]), rel=1e-12) and row["level_dba"] > 80
    assert row["risk_name"] == RISK_NAMES[int(node["risk"][0])] and row["regime_name"] == REGIME_NAMES[
        int(node["regime"][0])]
    assert main(["predict", "squeal", "--vehicle-class", "emu", "--aoa-mrad", "13"]) == 0
    assert "level [dB(A)]" in capsys.readouterr().out


def test_a_history_gives_a_row_per_friction_state_as_the_squeal_node_predicts(capsys, site_values, sample_passes):
    # The per-state table of the README's squeal section: its shares are the squeal model's on the
    # sample, and the onset follows the friction peaks (saturation creepage ~ mu0, reduced_kalker).
    from rail_monitor.core.passes import FRICTION_BY_NAME, rejection_reasons, with_class_defaults
    from rail_monitor.core.site import site_from_values
    from rail_monitor.squeal.config import squeal_config
    from rail_monitor.squeal.predict import predict

    from conftest import SAMPLE

    assert main(["predict", "squeal", "--history", str(SAMPLE), "--json"]) == 0
    rows = {r["friction_state"]: r for r in json.loads(capsys.readouterr().out)["friction_states"]}
    site = site_from_values(site_values)
    table = with_class_defaults(sample_passes.take(rejection_reasons(sample_passes, site) == ""), site)
    unstable = predict(squeal_config(site_values), site, table)["unstable"]
    for name, r in rows.items():
        sel = table.friction_state == FRICTION_BY_NAME[name]
        assert r["passes"] == sel.sum() and r["unstable_share"] == pytest.approx(unstable[sel].mean(), abs=1e-12)
    onset = [rows[n]["onset_mrad"] for n in ("contaminated", "wet", "dry", "friction_modifier")]
    assert onset == sorted(onset)
    assert rows["friction_modifier"]["unstable_share"] == 0.0
    assert 6.3 <= rows["dry"]["friction_modifier_cut_dba"] <= 22.8       # Eadie & Santoro 2006's range
