"""Figures of the what-if commands (PNG, matplotlib's Agg backend: no display needed); the run
report's figures are in :mod:`rail_monitor.report.plots`."""

from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rail_monitor.models.squeal import REGIME_REVERSE_SLIP


def squeal_sweep(rows: dict[str, np.ndarray], path: str | Path, title: str = "") -> Path:
    """Amplitude and relative level against crabbing velocity (the shape of the UQ paper's Figure 7a)."""
    vc = rows["crabbing_velocity_mps"]
    amp = rows["velocity_amplitude_mps"]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.0), constrained_layout=True)
    ax1.plot(vc, amp, "-", label="energy balance")
    if "ode_amplitude_mps" in rows:
        ax1.plot(vc, rows["ode_amplitude_mps"], "o", mfc="none", label="time integration")
    ax1.plot(vc, vc, ":", color="grey", label="A w = Vc")
    reverse = rows["regime"] == REGIME_REVERSE_SLIP
    if np.any(reverse):
        ax1.plot(vc[reverse], amp[reverse], "x", color="tab:red", label="with reverse slip (whole curve)")
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
    return _save(fig, path)


def _save(fig, path: str | Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def track_receptance(frequency: np.ndarray, curves: dict[str, np.ndarray], path: str | Path, title: str = "") -> Path:
    """Magnitude and phase of vertical receptances [m/N] against frequency [Hz] (log-log)."""
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.0), constrained_layout=True)
    for label, r in curves.items():
        ax1.loglog(frequency, np.abs(r), label=label)
        ax2.semilogx(frequency, np.degrees(np.angle(r)), label=label)
    ax1.set_ylabel("|receptance| [m/N]")
    ax1.legend(loc="lower left", fontsize="small")
    ax2.set_ylabel("phase [deg]")
    ax2.set_xlabel("frequency [Hz]")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
    if title:
        ax1.set_title(title)
    return _save(fig, path)


def corrugation_growth(wavelength: np.ndarray, curves: dict[str, np.ndarray], path: str | Path,
                       title: str = "") -> Path:
    """Growth per axle pass g [1/axle pass] against wavelength [m], one curve per speed distribution."""
    fig, ax = plt.subplots(figsize=(6.4, 4.2), constrained_layout=True)
    for label, g in curves.items():
        ax.semilogx(1e3 * wavelength, g, "o-", ms=3, label=label)
    ax.axhline(0.0, color="grey", lw=0.8)
    ax.set_xlabel("wavelength [mm]")
    ax.set_ylabel("growth g per axle pass [-]")
    ax.legend(fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
    if title:
        ax.set_title(title)
    return _save(fig, path)


def grinding_cycles(axle_passes: np.ndarray, curves: dict[str, tuple[np.ndarray, np.ndarray]], threshold_m: float,
                    visit_cost: float, path: str | Path, title: str = "") -> Path:
    """The UQ paper's Figure 2 in shape: (a) the worst band's r.m.s. roughness [um] over axle passes,
    ground at its threshold, (b) the cumulative grinding cost; one curve per speed distribution
    (curves: label -> (roughness [m], grinds made) per axle pass)."""
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.6), constrained_layout=True)
    for label, (z, grinds) in curves.items():
        top.plot(axle_passes, 1e6 * z, lw=1, label=label)
        bottom.step(axle_passes, visit_cost * grinds, where="post", label=f"{label}: {grinds[-1]} grinds")
    top.axhline(1e6 * threshold_m, color="tab:red", lw=0.8, ls="--", label="intervention threshold")
    top.set_ylabel("worst band r.m.s. [um]")
    top.set_title("(a) corrugation growth", fontsize="medium")
    bottom.set_ylabel("cumulative grinding cost [cost unit]")
    bottom.set_title("(b) grinding cost", fontsize="medium")
    bottom.set_xlabel("axle passes [-]")
    for ax in (top, bottom):
        ax.legend(fontsize="small")
        ax.grid(True, alpha=0.3)
    if title:
        fig.suptitle(textwrap.fill(title, 90), fontsize="small")
    return _save(fig, path)


def noise_spectra(band_hz: np.ndarray, panels: dict[str, dict[str, np.ndarray]], path: str | Path,
                  title: str = "") -> Path:
    """A-weighted 1/3-octave Lp [dB(A)] against band centre [Hz], one panel per group of spectra (the
    shapes of the UQ paper's Figure 3: spectra at several speeds; after roughness growth of various times)."""
    fig, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(6.4, 3.2 * len(panels)), constrained_layout=True,
                             squeeze=False)
    for ax, (heading, curves) in zip(axes[:, 0], panels.items(), strict=True):
        for label, lp in curves.items():
            ax.semilogx(band_hz, lp, "o-", ms=3, label=label)
        ax.set_ylabel("Lp,A per band [dB(A)]")
        ax.set_title(heading, fontsize="medium")
        ax.legend(fontsize="small")
        ax.grid(True, which="both", alpha=0.3)
    axes[-1, 0].set_xlabel("1/3-octave band centre [Hz]")
    if title:
        fig.suptitle(textwrap.fill(title, 90), fontsize="small")
    return _save(fig, path)
