"""Regenerate cnossos_rules.png, docs/models.md's figure of the two CNOSSOS-EU interpolation rules:

    ros2_ws/run python docs/images/cnossos_rules.py

A 4-axle vehicle (cast-iron tread brakes, 1200 mm wheels, contact filter 50 kN / 920 mm) at 80 km/h
on class E rail, bi-block sleepers on medium pads: NoiseModelling's section 1 and 2 cases."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rail_monitor.models import cnossos as cn
from rail_monitor.models import cnossos_bands as cb
from rail_monitor.models.levels import level, power

T = cn.tables()
V = 80 / 3.6
_, A3 = cn.contact_filter(50e3, 0.92)
_, TRACK = cn.track_transfer("biblock", 500e6)
_, VEHICLE = cn.vehicle_transfer(1.2)


def rolling_lw0(rule: str, joints: bool) -> np.ndarray:
    impact = cn.impact_roughness(0.01) if joints else None
    lr = cb.band_roughness(cn.rail_roughness("E"), cn.wheel_roughness("cast_iron", rule), A3, V, rule=rule,
                           impact_db=impact)
    p = cn.rolling_sound_power(lr, 4, TRACK, VEHICLE)
    return level(power(p.track) + power(p.vehicle))


fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7.0, 6.0), constrained_layout=True)
x = np.arange(len(T.band_hz))
for joints, style in ((False, "-"), (True, "--")):
    ref, nm = rolling_lw0("reference", joints), rolling_lw0("noisemodelling", joints)
    label = "one joint per 100 m" if joints else "no joints"
    ax1.plot(x, ref, style, color="tab:blue", label=f"reference, {label}")
    ax1.plot(x, nm, style, color="tab:orange", label=f"noisemodelling, {label}")
    ax2.plot(x, ref - nm, style, color="k", label=label)
ax1.set_ylabel("rolling L_W,0 per vehicle [dB re 1 pW]")
ax1.legend(fontsize="small")
ax1.grid(True, alpha=0.3)
ax1.set_title("CNOSSOS-EU rolling noise, 80 km/h: the two interpolation rules")
ax2.axhline(0.0, color="grey", lw=0.8)
ax2.set_ylabel("reference - noisemodelling [dB]")
ax2.set_xticks(x[::3], [f"{f:g}" for f in T.band_hz[::3]])
ax2.set_xlabel("1/3-octave band [Hz]")
ax2.legend(fontsize="small")
ax2.grid(True, alpha=0.3)
fig.savefig(Path(__file__).with_name("cnossos_rules.png"), dpi=100)
