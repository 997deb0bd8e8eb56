"""Figures (PNG, matplotlib's Agg backend: no display needed)."""

from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rail_monitor.models.squeal import REGIME_STICK_SLIP_BOUND


def squeal_sweep(rows: dict[str, np.ndarray], path: str | Path, title: str = "") -> Path:
    """Amplitude and relative level against crabbing velocity (the shape of the UQ paper's Figure 7a)."""
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


# -- run report (rail_monitor.app.report) -----------------------------------------------------------
def _dates(stamp_ns: np.ndarray) -> np.ndarray:
    return np.asarray(stamp_ns, np.int64).astype("datetime64[ns]")


def corrugation_history(states: dict[str, np.ndarray], path: str | Path, bands_shown: int = 4) -> Path:
    """r.m.s. roughness of the bands nearest their thresholds against pass time, with the thresholds
    (dashed), grinding events (vertical lines) and the forecast of the worst band (dotted, to its
    threshold at the forecast time)."""
    t = _dates(states["stamp"])
    amp, thr, lam = states["amplitude_m"], states["threshold_m"], states["wavelength_m"]
    shown = np.argsort(-(amp[-1] / thr[-1]))[:bands_shown]
    fig, ax = plt.subplots(figsize=(8.0, 4.6), constrained_layout=True)
    for j, b in enumerate(shown):
        colour = f"C{j}"
        ax.semilogy(t, 1e6 * amp[:, b], color=colour, label=f"{1e3 * lam[b]:.1f} mm")
        ax.axhline(1e6 * thr[-1, b], color=colour, ls="--", lw=0.9)
    w = int(states["worst_band"][-1])
    due = int(states["grinding_due_time"][-1])
    if due and w in shown:
        ax.semilogy([t[-1], _dates(np.array([due]))[0]], [1e6 * amp[-1, w], 1e6 * thr[-1, w]], ":", color="k",
                    label=f"forecast {1e3 * lam[w]:.1f} mm: {str(_dates(np.array([due]))[0])[:10]}")
    for g in sorted(set(states["last_grinding_time"].tolist()) - {0}):
        ax.axvline(_dates(np.array([g]))[0], color="grey", lw=1.5, label="grinding")
    ax.set_ylabel("r.m.s. roughness [um] (dashed: intervention threshold)")
    ax.set_xlabel("pass time (UTC)")
    ax.set_title("Corrugation per 1/3-octave wavelength band (the bands nearest their thresholds)")
    ax.legend(fontsize="small", ncol=2)
    ax.grid(True, which="both", alpha=0.3)
    fig.autofmt_xdate()
    return _save(fig, path)


def noise_history(noise: dict[str, dict[str, np.ndarray]], before: dict, after: dict, path: str | Path) -> Path:
    """LpAeq,Tp per pass against pass time per model, and A-weighted spectra of a reference pass on
    the post-grinding and the final rail."""
    from rail_monitor.models.iec61672 import a_weighting_db

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8.0, 7.6), constrained_layout=True)
    for j, (model, nz) in enumerate(noise.items()):
        ax1.plot(_dates(nz["stamp_ns"]), nz["lpaeq_tp_dba"], ".", ms=2, color=f"C{j}", label=model)
    ax1.set_ylabel("LpAeq,Tp at the receiver [dB(A)]")
    ax1.set_xlabel("pass time (UTC)")
    ax1.legend(markerscale=6)
    ax1.grid(True, alpha=0.3)
    for j, model in enumerate(m for m in before if m != "label"):
        f = before[model].band_centre_hz
        aw = a_weighting_db(f)
        ax2.semilogx(f, before[model].lp_db[0] + aw, "o--", ms=3, color=f"C{j}", label=f"{model}, post-grinding")
        ax2.semilogx(f, after[model].lp_db[0] + aw, "o-", ms=3, color=f"C{j}", label=f"{model}, final state")
    ax2.set_xlabel("1/3-octave band centre [Hz]")
    ax2.set_ylabel("Lp,A per band [dB(A)]")
    ax2.set_title(f"Spectra before and after roughness growth: {before['label']}", fontsize="medium")
    ax2.legend(fontsize="small")
    ax2.grid(True, which="both", alpha=0.3)
    return _save(fig, path)


def squeal_passes(squeal: dict[str, np.ndarray], curves: dict, path: str | Path) -> Path:
    """Squeal velocity amplitude against crabbing velocity: the model per friction state (lines, for a
    reference pass) and every pass (points, its own speed, load and class)."""
    from rail_monitor.core.passes import FRICTION_NAMES

    fig, ax = plt.subplots(figsize=(8.0, 4.8), constrained_layout=True)
    for j, (state, name) in enumerate(FRICTION_NAMES.items()):
        rows = squeal["friction_state"] == state
        ax.plot(squeal["crabbing_velocity_mps"][rows], squeal["velocity_amplitude_mps"][rows], ".", ms=3,
                color=f"C{j}", alpha=0.5, label=f"passes, {name}")
        if name in curves:
            c = curves[name]
            ax.plot(c["crabbing_velocity_mps"], c["velocity_amplitude_mps"], "-", color=f"C{j}",
                    label=f"model, {name} ({curves['label']})")
    ax.set_xlabel("crabbing velocity Vc [m/s]")
    ax.set_ylabel("lateral velocity amplitude A w [m/s]")
    ax.legend(fontsize="small", ncol=2)
    ax.grid(True, alpha=0.3)
    return _save(fig, path)


def speed_distribution(speeds: np.ndarray, advisory, path: str | Path) -> Path:
    """The history's pass speeds next to the advised distribution (same mean, least peak growth)."""
    fig, ax = plt.subplots(figsize=(8.0, 4.2), constrained_layout=True)
    if advisory is not None and len(advisory.speed_bin_centres_mps):
        c = np.asarray(advisory.speed_bin_centres_mps)
        width = float(np.min(np.diff(c))) if len(c) > 1 else 0.5
        ax.bar(c - width / 4, advisory.current_probability, width / 2, label="recent passes (axle-weighted)")
        ax.bar(c + width / 4, advisory.recommended_probability, width / 2,
               label=f"advised (peak growth -{100 * advisory.peak_growth_reduction:.0f} %)")
        bins = np.append(c - width / 2, c[-1] + width / 2)
    else:
        bins = 30
    hist, edges = np.histogram(speeds, bins=bins)
    ax.stairs(hist / max(hist.sum(), 1), edges, color="k", label="whole history (passes)")
    ax.set_xlabel("pass speed [m/s]")
    ax.set_ylabel("share of traffic [-]")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    return _save(fig, path)
