"""rail-monitor predict passby-audio (rail_monitor.whatif.audio): the predicted pass, written as audio
and read back by the pass-by processor, gives back its predicted levels (issue 54)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.io import wavfile

from rail_monitor.cli import main
from rail_monitor.models import iso3095
from rail_monitor.models.squeal_detection import detect_squeal
from rail_monitor.site_file import load_parameter_file
from rail_monitor.whatif.audio import pass_audio

from conftest import SITE_FILE, band_noise_tolerance_db, band_readings_db


def test_the_predicted_pass_read_back_gives_its_predicted_levels():
    """The shipped site's first class at its mean speed, dry, no angle of attack (no squeal): the
    processor reads LpAeq,Tp and TEL within 0.15 dB of the prediction, LpAFmax within 1 dB (the
    noise's own fluctuation under the F time weighting: +0.5 dB here), each band against what the
    filters pass of the predicted spectrum (conftest.band_readings_db) within
    conftest.band_noise_tolerance_db, and those readings within 1 dB of the predicted bands (the
    class 1 filters' effective bandwidth and skirts over the predicted spectrum's steps: 0.66 dB at
    most here)."""
    a = pass_audio(load_parameter_file(SITE_FILE), seed=7)
    assert np.isnan(a.squeal_hz)
    r = iso3095.passby_levels(a.pressure_pa, a.fs_hz, a.pass_start_s, a.pass_start_s + a.pass_time_s)
    assert r.lpaeq_tp_db == pytest.approx(a.lpaeq_tp_dba, abs=0.15)
    assert r.tel_db == pytest.approx(a.tel_dba, abs=0.15)
    assert r.lpafmax_db == pytest.approx(a.lpafmax_dba, abs=1.0)
    bands = np.rint(10 * np.log10(a.band_centre_hz / 1000.0)).astype(int)
    expected = band_readings_db(a.lp_db, bands)
    assert np.all(np.abs(r.band_levels_db - expected) <= band_noise_tolerance_db(bands, a.pass_time_s))
    assert np.all(np.abs(expected - a.lp_db) <= 1.0)


def test_a_squealing_pass_is_heard_squealing_at_its_frequency(tmp_path, capsys):
    """Wet rail at 10 mrad: the squeal model finds the pass unstable; the WAV written by the command
    line, read back, squeals at the predicted frequency (within the Doppler shift of the pass's
    middle, 1 %) for most of the pass."""
    out = tmp_path / "pass.wav"
    assert main(["predict", "passby-audio", "--output", str(out), "--friction", "wet", "--aoa-mrad", "10",
                 "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["squeal_hz"] > 0
    fs, p = wavfile.read(out)
    d = detect_squeal(p.astype(float), fs, facts["pass_start_s"], facts["pass_start_s"] + facts["pass_time_s"])
    assert d.squeal and d.frequency_hz == pytest.approx(facts["squeal_hz"], rel=0.01) and d.share > 0.8
    assert main(["predict", "passby-audio", "--output", str(out)]) == 2  # never replaces a file
    assert "exists" in capsys.readouterr().err
