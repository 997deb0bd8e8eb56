"""The report's listening section: the loudest predicted passes made audible
(rail_monitor.whatif.audio), each beside its measured audio where the station's archive kept it
(rail_monitor.station.archive), so an engineer or a resident hears what grinding or a friction
modifier changes.

Every file is written as 32-bit float WAV on one scale, full scale = FULL_SCALE_PA (a 120 dB
peak): the predicted pass from its pascals, the measured one from the recording times the
station's sensitivity (``station.*``); a recording whose sensitivity the site does not give is
copied as recorded and marked uncalibrated.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
from scipy.io import wavfile

from rail_monitor.bagio.wav import read_wav
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.friction import FRICTION_NAMES
from rail_monitor.core.timeutil import format_local_ns
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.report.run_data import RunData
from rail_monitor.station.config import station_config
from rail_monitor.station.pass_audio import audio_name, sensitivity
from rail_monitor.whatif.audio import pass_audio

FULL_SCALE_PA = 20.0     # 120 dB re 20 uPa at full scale
LISTEN_FS_HZ = 32_000.0  # enough for the 10 kHz band, a third smaller than 48 kHz
MARGIN_S = 2.0           # before and after the train


def listening(run: RunData, cfg: SiteConfig, out: Path, passes: int, archive: Path | None) -> list[dict]:
    """Write the audio of the ``passes`` loudest passes (predicted LpAFmax of the first noise model)
    into out/audio; one row per pass (its time, train, class, speed, predicted LpAFmax, and the
    files' names relative to out, '' where none)."""
    if passes <= 0 or not run.noise:
        return []
    model = sorted(run.noise)[0]
    noise = run.noise[model]
    at = {(int(s), str(t)): i for i, (s, t) in enumerate(zip(run.passes.stamp_ns, run.passes.train_id, strict=True))}
    loudest = [k for k in np.argsort(-noise["lpafmax_dba"], kind="stable")
               if (int(noise["stamp_ns"][k]), str(noise["train_id"][k])) in at][:passes]
    folder = out / "audio"
    folder.mkdir(parents=True, exist_ok=True)
    scale = _measured_scale(cfg)
    rows = []
    for n, k in enumerate(loudest):
        key = (int(noise["stamp_ns"][k]), str(noise["train_id"][k]))
        p = run.passes.take(slice(at[key], at[key] + 1))
        a = pass_audio(cfg.values, str(p.vehicle_class[0]), float(p.speed_mps[0]), int(p.vehicle_count[0]) or None,
                       FRICTION_NAMES[int(p.friction_state[0])], 1e3 * float(p.angle_of_attack_rad[0]), model,
                       fs_hz=LISTEN_FS_HZ, margin_s=MARGIN_S, seed=n)
        stem = Path(audio_name(*key)).stem
        predicted = folder / f"{stem}_predicted.wav"
        wavfile.write(predicted, int(LISTEN_FS_HZ), (a.pressure_pa / FULL_SCALE_PA).astype(np.float32))
        measured = _measured(archive, key, folder / f"{stem}_measured.wav", scale)
        rows.append({"pass time (local)": format_local_ns(key[0], cfg.site.time_zone, seconds=True),
                     "train": key[1], "class": str(p.vehicle_class[0]), "km/h": 3.6 * float(p.speed_mps[0]),
                     "friction": FRICTION_NAMES[int(p.friction_state[0])],
                     f"predicted LpAFmax ({model}) dB(A)": float(noise["lpafmax_dba"][k]),
                     "predicted": str(predicted.relative_to(out)), "measured": measured})
    return rows


def _measured_scale(cfg: SiteConfig) -> tuple[float | None, int]:
    """Pascals per unit of the station's recordings (None where the site does not say), and their channel."""
    st = station_config(cfg.values)
    try:
        return sensitivity(st.sensitivity_pa_per_unit, st.calibration_file, st.calibration_db, st.channel), st.channel
    except RailMonitorError:
        return None, st.channel


def _measured(archive: Path | None, key: tuple[int, str], dest: Path, scale: tuple[float | None, int]) -> str:
    """The archived recording of the pass on the report's scale ('' when the archive has none)."""
    if archive is None:
        return ""
    source = archive / audio_name(*key)
    if not source.is_file():
        return ""
    pa_per_unit, channel = scale
    if pa_per_unit is None:
        shutil.copyfile(source, dest)
        return f"{dest.parent.name}/{dest.name} (uncalibrated)"
    fs, samples = read_wav(source, channel)
    wavfile.write(dest, int(fs), (samples * pa_per_unit / FULL_SCALE_PA).astype(np.float32))
    return f"{dest.parent.name}/{dest.name}"
