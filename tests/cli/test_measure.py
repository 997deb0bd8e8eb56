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


def test_a_trace_becomes_a_survey_that_batch_applies_as_if_it_were_in_the_history(tmp_path, capsys):
    """measure roughness --survey-bag writes the trace's spectrum as one RoughnessSurvey at --stamp;
    batch --surveys applies it (re-fitting K_b) exactly as it applies the same survey carried in the
    history bag: every corrugation state the same bits. A CSV is not a surveys bag: one line."""
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.bagio.reader import read_bag_events, read_messages, read_passes
    from rail_monitor.codec.typestore import CORRUGATION_STATE
    from rail_monitor.core.timeutil import format_iso_ns
    from rail_monitor.corrugation.surveys import KIND_SURVEY

    from conftest import SAMPLE

    rng = np.random.default_rng(15610)
    x = np.arange(0.0, 12.0, 0.001)
    z_um = 8.0 * np.sin(2 * np.pi * x / 0.05) + 3.0 * np.sin(2 * np.pi * x / 0.2) + rng.normal(0.0, 0.5, len(x))
    trace = tmp_path / "trace.csv"
    trace.write_text("distance_m,displacement_um\n"
                     + "".join(f"{a:.4f},{b:.5f}\n" for a, b in zip(x, z_um, strict=True)))
    passes = read_passes(SAMPLE).take(slice(0, 400))
    stamp = int(passes.stamp_ns[200])
    survey = tmp_path / "survey"
    assert main(["measure", "roughness", str(trace), "--json", "--survey-bag", str(survey),
                 "--stamp", format_iso_ns(stamp)]) == 0
    spectrum = json.loads(capsys.readouterr().out)
    (event,) = read_bag_events(survey)
    assert event.kind == KIND_SURVEY and event.stamp_ns == stamp
    rms = np.array(spectrum["rms_m"])
    np.testing.assert_array_equal(event.amplitude_m, rms[rms > 0])
    alone, within = tmp_path / "alone", tmp_path / "within"
    write_passes_bag(passes, alone, "curve_250")
    write_passes_bag(passes, within, "curve_250", events=[event])
    for src, extra in ((alone, ["--surveys", str(survey)]), (within, [])):
        assert main(["batch", str(src), "--no-report", "--output", str(tmp_path / f"{src.name}_out"), *extra]) == 0
        assert "1 roughness survey(s) and grinding event(s) read: 1 applied" in capsys.readouterr().out
    a, b = (read_messages(tmp_path / f"{n}_out", [CORRUGATION_STATE])[CORRUGATION_STATE] for n in ("alone", "within"))
    assert len(a) == len(b) == 400
    assert all(np.array_equal(s.amplitude_m, t.amplitude_m) and np.array_equal(s.k_b_by_friction, t.k_b_by_friction)
               for s, t in zip(a, b, strict=True))
    assert not np.array_equal(a[0].k_b_by_friction, a[-1].k_b_by_friction)  # the survey re-fitted K_b
    assert main(["batch", str(alone), "--no-report", "--output", str(tmp_path / "x"), "--surveys", str(trace)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no rail_msgs/msg/RoughnessSurvey in it" in err[0]
