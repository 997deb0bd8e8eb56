"""Regenerate mechanics_vs_cnossos.png, the README's figure of the mechanics model (modal wheel, the default
contact filter A3 at the pass's contact length)
against CNOSSOS-EU for the same vehicle, track and roughness:

    ros2_ws/run python docs/images/mechanics_vs_cnossos.py

The bundled site (src/rail_monitor/config/curve_250.yaml): its freight wagon (920 mm wheels,
cast-iron brakes) on its UIC60 ballasted track, class E rail, at 80 and 120 km/h; sound power
L_W,0 per vehicle per component and band."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rail_monitor.core.passes import FRICTION_DRY, PassTable, with_class_defaults
from rail_monitor.models.iec61672 import a_weighting_db
from rail_monitor.models.levels import level, power
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.site_file import load_parameter_file, load_site

SITE = Path(__file__).resolve().parents[2] / "src" / "rail_monitor" / "config" / "curve_250.yaml"
model = RollingNoiseModel(load_site(SITE), noise_config(load_parameter_file(SITE)))
speeds = np.array([80.0, 120.0]) / 3.6
passes = with_class_defaults(PassTable(
    stamp_ns=[1, 2], train_id=["A", "B"], vehicle_class=["freight"] * 2, vehicle_count=[4, 4], axle_count=[0, 0],
    speed_mps=speeds, angle_of_attack_rad=[0.0, 0.0], wheel_load_n=[0.0, 0.0], friction_state=[FRICTION_DRY] * 2,
    train_length_m=[0.0, 0.0]), model.site)
mech = model.vehicle_sound_power(passes, "mechanics")
cnos = model.vehicle_sound_power(passes, "cnossos")
x = np.arange(len(model.band_hz))
aw = a_weighting_db(model.band_hz)

fig, axes = plt.subplots(1, 2, sharey=True, figsize=(10.0, 4.6), constrained_layout=True)
for i, ax in enumerate(axes):
    for name, color in (("rail", "tab:blue"), ("sleeper", "tab:green"), ("wheel", "tab:red")):
        ax.plot(x, mech[name][i], color=color, label=f"mechanics: {name}")
    total_m = level(sum(power(v[i]) for v in mech.values()))
    total_c = level(sum(power(v[i]) for v in cnos.values()))
    ax.plot(x, total_m, "k-", lw=2, label="mechanics: total")
    ax.plot(x, cnos["track"][i], "--", color="tab:blue", label="CNOSSOS-EU: track")
    ax.plot(x, cnos["vehicle"][i], "--", color="tab:red", label="CNOSSOS-EU: vehicle")
    ax.plot(x, total_c, "k--", lw=2, label="CNOSSOS-EU: total")
    gap = level(np.sum(power(total_m + aw))) - level(np.sum(power(total_c + aw)))
    ax.set_title(f"freight, {speeds[i] * 3.6:.0f} km/h: mechanics - CNOSSOS {gap:+.1f} dB(A)", fontsize="medium")
    ax.set_xticks(x[::3], [f"{f:g}" for f in model.band_hz[::3]])
    ax.set_xlabel("1/3-octave band [Hz]")
    ax.set_ylim(60, 125)
    ax.grid(True, alpha=0.3)
axes[0].set_ylabel("L_W,0 per vehicle [dB re 1 pW]")
axes[1].legend(fontsize="small", loc="lower center", ncol=2)
fig.savefig(Path(__file__).with_name("mechanics_vs_cnossos.png"), dpi=90)
