"""rail-monitor predict noise as a user runs it (rail_monitor.cli.predict_noise), in-process."""

from __future__ import annotations

import json

import numpy as np
import pytest
from noise.test_predict import _passes

from rail_monitor.cli import main
from rail_monitor.models.corrugation_bands import band_limits, wavelength_bands
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import Corrugation
from rail_monitor.site_file import load_parameter_file, load_site

from conftest import SITE_FILE


def test_predict_noise_json_equals_the_library(tmp_path, capsys):
    model = RollingNoiseModel(load_site(SITE_FILE), noise_config(load_parameter_file(SITE_FILE)))
    png = tmp_path / "spectra.png"
    assert main(["predict", "noise", "--vehicle-class", "emu", "--speed", "20", "40", "--vehicles", "4",
                 "--growth-days", "180", "--json", "--plot", str(png)]) == 0
    doc = json.loads(capsys.readouterr().out)
    runs = {(r["model"], r["growth_days"]): r["passes"] for r in doc["results"]}
    assert set(runs) == {("cnossos", 0.0), ("cnossos", 180.0), ("mechanics", 0.0), ("mechanics", 180.0)}
    # Day 0 is the rail just after grinding: no increase; the CLI's numbers are the library's.
    assert runs[("cnossos", 0.0)][0]["roughness_growth_increase_db"] == pytest.approx(0.0, abs=1e-12)
    assert runs[("cnossos", 180.0)][0]["roughness_growth_increase_db"] > 0.5
    assert len(runs[("mechanics", 0.0)][1]["lp_db"]) == len(doc["band_centre_hz"]) == 24
    post = 0.5 * band_limits(wavelength_bands(0.01, 1.0))
    want = model.predict(_passes(model.site, "emu", [20.0, 40.0]), "mechanics", Corrugation(
        wavelength_bands(0.01, 1.0), post, post)).lpaeq_tp_dba
    np.testing.assert_allclose([p["lpaeq_tp_dba"] for p in runs[("mechanics", 0.0)]], want, rtol=1e-12)
    assert png.stat().st_size > 10_000


def test_a_speed_out_of_range_is_one_line_and_exit_2(capsys):
    assert main(["predict", "noise", "--speed", "-3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "(0, 120] m/s" in err


def test_the_table_names_each_component(capsys):
    assert main(["predict", "noise", "--speed", "20", "--model", "both"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("# site curve_250, emu") and len(out) == 5
    assert "since grinding" in out[1] and "baseline rail roughness" in out[1]   # the increase's reference
    assert "rail" in out[4] and "track" in out[3]
