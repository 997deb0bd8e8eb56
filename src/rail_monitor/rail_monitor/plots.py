"""Figures (PNG, matplotlib's Agg backend: no display needed)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rail_monitor.models.squeal import REGIME_STICK_SLIP_BOUND


def squeal_sweep(rows: dict[str, np.ndarray], path: str | Path, title: str = "") -> Path:
    """Amplitude and relative level against crabbing velocity (the shape of the seed's Figure 7a)."""
    vc = rows["crabbing_velocity_mps"]
    amp = rows["velocity_amplitude_mps"]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.0), constrained_layout=True)
    ax1.plot(vc, amp, "-", label="closed form (energy balance)")
    if "ode_amplitude_mps" in rows:
        ax1.plot(vc, rows["ode_amplitude_mps"], "o", mfc="none", label="time integration")
    ax1.plot(vc, vc, ":", color="grey", label="A w = Vc")
    bound = rows["regime"] == REGIME_STICK_SLIP_BOUND
    if np.any(bound):
        ax1.plot(vc[bound], amp[bound], "x", color="tab:red", label="stick-slip bound")
    ax1.set_ylabel("velocity amplitude A w [m/s]")
    ax1.legend(loc="upper left")
    ax1.grid(True, alpha=0.3)
    level = np.where(np.isfinite(rows["relative_level_db"]), rows["relative_level_db"], np.nan)
    ax2.plot(vc, level, "-")
    ax2.set_xlabel("crabbing velocity Vc [m/s]")
    ax2.set_ylabel("relative level 20 lg(A w / A w_ref) [dB]")
    ax2.grid(True, alpha=0.3)
    if title:
        ax1.set_title(title)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
