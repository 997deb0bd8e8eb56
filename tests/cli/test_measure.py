"""rail-monitor measure passby: a station's WAV files reduced to the ISO 3095 levels (issue 54)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.io import wavfile

from rail_monitor.cli import main
from rail_monitor.models.iso3095 import passby_levels

FS = 48_000
P0 = 20e-6


def _files(tmp_path):
    """A calibrator (94 dB, 1 kHz) recorded at 0.5 of full scale, and a pass: a 1 kHz tone at 0.05 of
    full scale (74 dB) between 1 s and 3 s of a 4 s record, in 16-bit WAV."""
    t = np.arange(4 * FS) / FS
    cal = 0.5 * np.sqrt(2) * np.sin(2 * np.pi * 1000 * t[:FS])
    tone = np.where((t >= 1.0) & (t < 3.0), 0.05 * np.sqrt(2) * np.sin(2 * np.pi * 1000 * t), 0.0)
    paths = tmp_path / "cal.wav", tmp_path / "pass.wav"
    for path, x in zip(paths, (cal, tone), strict=True):
        wavfile.write(path, FS, np.round(x * 32767).astype(np.int16))
    return paths


def test_the_json_holds_every_key_and_the_levels_of_the_library(tmp_path, capsys):
    cal, wav = _files(tmp_path)
    assert main(["measure", "passby", str(wav), "--calibration-file", str(cal), "--start-s", "1", "--end-s", "3",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) >= {"lpaeq_tp_db", "lpafmax_db", "tel_db", "sel_db", "band_centres_hz", "band_levels_db", "tones"}
    assert out["lpaeq_tp_db"] == pytest.approx(74.0, abs=0.02)          # the tone over exactly its 2 s
    assert out["tel_db"] == pytest.approx(out["lpaeq_tp_db"], abs=0.02)   # nothing outside the pass
    assert out["sel_db"] == pytest.approx(74.0 + 10 * np.log10(2.0), abs=0.02)
    assert len(out["band_levels_db"]) == len(out["band_centres_hz"]) == 24
    assert out["tones"][0]["frequency_hz"] == pytest.approx(1000.0, abs=1.0)
    assert set(out["tones"][0]) == {"frequency_hz", "level_db", "audibility_db"}
    assert out["squeal"]["detected"] and out["squeal"]["frequency_hz"] == pytest.approx(1000.0, abs=5.0)
    assert out["squeal"]["duration_s"] == pytest.approx(2.0, abs=0.1) and not out["squeal"]["flanging"]
    fs, samples = wavfile.read(wav)
    lib = passby_levels(samples / 32768.0 * out["sensitivity_pa_per_unit"], fs, 1.0, 3.0)
    assert out["lpafmax_db"] == pytest.approx(lib.lpafmax_db, abs=1e-9)


def test_the_table_and_the_refusals(tmp_path, capsys):
    _, wav = _files(tmp_path)
    assert main(["measure", "passby", str(wav), "--sensitivity", "1.0"]) == 0
    assert "LpAeq,Tp" in capsys.readouterr().out
    assert main(["measure", "passby", str(wav)]) == 2
    assert capsys.readouterr().err.strip() == ("rail-monitor: error: give one of --calibration-file (with "
                                               "--calibration-db) or --sensitivity")
    assert main(["measure", "passby", str(wav), "--sensitivity", "1", "--start-s", "3", "--end-s", "9"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not inside the record" in err[0] and str(wav) in err[0]
    assert main(["measure", "passby", str(tmp_path / "none.wav"), "--sensitivity", "1"]) == 2
    assert "no such file" in capsys.readouterr().err


def test_measure_roughness_reads_a_trolley_csv(tmp_path, capsys):
    """A trace CSV in micrometres: the band of its 10 um sinusoid at 50.1 mm reads 16.99 dB re 1 um
    to 0.1 dB; an unevenly spaced trace is one line naming the file."""
    x = np.arange(0.0, 10.0, 0.001)
    z_um = 10.0 * np.sin(2 * np.pi * x / 10 ** -1.3)
    path = tmp_path / "trace.csv"
    path.write_text("# trolley run 1\ndistance_m,displacement_um\n"
                    + "".join(f"{a:.4f},{b:.5f}\n" for a, b in zip(x, z_um, strict=True)))
    assert main(["measure", "roughness", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    k = int(np.argmin(np.abs(np.log(np.array(out["wavelength_m"]) / 10 ** -1.3))))
    assert out["level_db"][k] == pytest.approx(20 * np.log10(10 / np.sqrt(2)), abs=0.1)
    bad = tmp_path / "bad.csv"
    bad.write_text("distance_m,displacement_um\n" + "".join(f"{a * a:.6f},0\n" for a in range(20)))
    assert main(["measure", "roughness", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not evenly spaced" in err[0] and str(bad) in err[0]
