"""The run report's figures (matplotlib, Agg backend): each function returns a Figure, which the
report saves as PNG for the page and as a page of the PDF.

Conventions: times on the site's local clock (its IANA zone, named on the axis), speeds in km/h,
roughness in µm with plain-number log ticks, thresholds and limits drawn and named in the legend,
passes coloured by vehicle class.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.dates as mdates
import matplotlib.pyplot as plt
import matplotlib.ticker as mticker
import numpy as np
from matplotlib.figure import Figure

from rail_monitor.core.passes import FRICTION_NAMES, KMH_PER_MPS
from rail_monitor.core.timeutil import time_zone
from rail_monitor.report.tables import METRIC_LABELS

CLASS_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive")


def dates(stamp_ns: np.ndarray) -> np.ndarray:
    """Stamps [ns] as numpy datetimes, what matplotlib plots on a date axis."""
    return np.asarray(stamp_ns, np.int64).astype("datetime64[ns]")


def _time_axis(ax, zone: str) -> None:
    tz = time_zone(zone)
    locator = mdates.AutoDateLocator(tz=tz)
    ax.xaxis.set_major_locator(locator)
    ax.xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator, tz=tz))
    ax.set_xlabel(f"pass time ({zone})")


def plain_log_ticks(axis) -> None:
    """Log-axis labels as plain numbers (0.5, 1, 2, 5, 10), not powers of ten."""
    def major(v: float, _pos: int) -> str:
        return f"{v:g}"

    def minor(v: float, _pos: int) -> str:
        mantissa = round(v / 10 ** math.floor(math.log10(v)), 6) if v > 0 else 0
        return f"{v:g}" if mantissa in (2.0, 5.0) else ""

    axis.set_major_formatter(mticker.FuncFormatter(major))
    axis.set_minor_formatter(mticker.FuncFormatter(minor))


def class_colours(classes: list[str]) -> dict[str, str]:
    return {c: CLASS_COLOURS[i % len(CLASS_COLOURS)] for i, c in enumerate(classes)}


def corrugation(states: Mapping[str, np.ndarray], zone: str, bands_shown: int = 4) -> Figure:
    """r.m.s. roughness of the bands nearest their thresholds against pass time, with each band's
    threshold (dashed), grinding events and the worst band's forecast to its threshold (dotted)."""
    t = dates(states["stamp"])
    amp, thr, lam = states["amplitude_m"], states["threshold_m"], states["wavelength_m"]
    shown = np.argsort(-(amp[-1] / thr[-1]))[:bands_shown]
    fig, ax = plt.subplots(figsize=(8.0, 4.6), constrained_layout=True)
    for j, b in enumerate(shown):
        ax.semilogy(t, 1e6 * amp[:, b], color=f"C{j}", label=f"{1e3 * lam[b]:.1f} mm band")
        ax.axhline(1e6 * thr[-1, b], color=f"C{j}", ls="--", lw=0.9, label=f"{1e3 * lam[b]:.1f} mm threshold")
    w = int(states["worst_band"][-1])
    due = int(states["grinding_due_time"][-1])
    if due and w in shown:
        end = dates(np.array([due]))[0]
        ax.semilogy([t[-1], end], [1e6 * amp[-1, w], 1e6 * thr[-1, w]], ":", color="k",
                    label=f"forecast, {1e3 * lam[w]:.1f} mm band")
    for k, g in enumerate(sorted(set(states["last_grinding_time"].tolist()) - {0})):
        ax.axvline(dates(np.array([g]))[0], color="grey", lw=1.5, label="grinding" if k == 0 else None)
    ax.set_ylabel("r.m.s. roughness [µm]")
    plain_log_ticks(ax.yaxis)
    _time_axis(ax, zone)
    ax.set_title("Corrugation per 1/3-octave wavelength band (the bands nearest their thresholds)")
    ax.legend(fontsize="small", ncol=2)
    ax.grid(True, which="both", alpha=0.3)
    return fig


def noise(t: Mapping[str, np.ndarray], models: list[str], lim: Mapping[str, Any], before: dict, after: dict,
          zone: str) -> Figure:
    """The alert's noise metric per pass against time, one panel per model, coloured by class, with
    the limit; and A-weighted spectra of a reference pass on the post-grinding and the final rail."""
    from rail_monitor.models.iec61672 import a_weighting_db

    fig, axes = plt.subplots(len(models) + 1, 1, figsize=(8.0, 3.0 * len(models) + 3.6), constrained_layout=True)
    ok = t["status"] == "processed"
    colours = class_colours(sorted(set(t["vehicle_class"][ok].tolist())))
    metric = METRIC_LABELS[lim["metric"]]
    for ax, model in zip(axes[:-1], models, strict=True):
        for cls, colour in colours.items():
            m = ok & (t["vehicle_class"] == cls)
            ax.plot(dates(t["stamp_ns"][m]), t[f"{model}_{lim['metric']}"][m], ".", ms=2, color=colour, label=cls)
        ax.axhline(lim["limit_dba"], color="tab:red", lw=1.2, label=f"limit {lim['limit_dba']:g} dB(A)")
        ax.set_ylabel(f"{metric} [dB(A)]")
        ax.set_title(f"{metric} at the receiver, {model} model", fontsize="medium")
        ax.legend(markerscale=6, fontsize="small", ncol=4)
        ax.grid(True, alpha=0.3)
        _time_axis(ax, zone)
    ax = axes[-1]
    for j, model in enumerate(m for m in before if m != "label"):
        f = before[model].band_centre_hz
        aw = a_weighting_db(f)
        ax.semilogx(f, before[model].lp_db[0] + aw, "o--", ms=3, color=f"C{j}", label=f"{model}, post-grinding")
        ax.semilogx(f, after[model].lp_db[0] + aw, "o-", ms=3, color=f"C{j}", label=f"{model}, final state")
    plain_log_ticks(ax.xaxis)
    ax.set_xlabel("1/3-octave band centre [Hz]")
    ax.set_ylabel("Lp,A per band [dB(A)]")
    ax.set_title(f"Spectra before and after roughness growth: {before['label']}", fontsize="medium")
    ax.legend(fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
    return fig


def squeal(squeal_data: Mapping[str, np.ndarray], curves: dict) -> Figure:
    """Squeal velocity amplitude against crabbing velocity: the model per friction state (lines, for a
    reference pass) and every pass (points, its own speed, load and class)."""
    fig, ax = plt.subplots(figsize=(8.0, 4.8), constrained_layout=True)
    for j, (state, name) in enumerate(FRICTION_NAMES.items()):
        rows = squeal_data["friction_state"] == state
        ax.plot(squeal_data["crabbing_velocity_mps"][rows], squeal_data["velocity_amplitude_mps"][rows], ".", ms=3,
                color=f"C{j}", alpha=0.5, label=f"passes, {name}")
        if name in curves:
            c = curves[name]
            ax.plot(c["crabbing_velocity_mps"], c["velocity_amplitude_mps"], "-", color=f"C{j}",
                    label=f"model, {name} ({curves['label']})")
    ax.set_xlabel("crabbing velocity Vc [m/s]")
    ax.set_ylabel("lateral velocity amplitude A w [m/s]")
    ax.set_title("Squeal: wheel velocity amplitude against crabbing velocity", fontsize="medium")
    ax.legend(fontsize="small", ncol=2)
    ax.grid(True, alpha=0.3)
    return fig


def squeal_fits(fits: Mapping[str, Mapping[str, np.ndarray]], zone: str) -> Figure:
    """Each friction state's creep curve as the site's measured squeal fitted it: the peak k1 and the
    falling slope k2, P50 with the P10-P90 band at each fit, the configured value dashed."""
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(8.0, 5.6), constrained_layout=True)
    for j, (state, f) in enumerate(fits.items()):
        t = dates(f["stamp_ns"])
        for ax, k in zip(axes, ("k1", "k2"), strict=True):
            ax.fill_between(t, f[f"{k}_p10"], f[f"{k}_p90"], step="post", color=f"C{j}", alpha=0.25)
            ax.step(t, f[f"{k}_p50"], where="post", color=f"C{j}", label=f"{state}, P50 (band: P10-P90)")
            ax.axhline(f[f"{k}_configured"][-1], color=f"C{j}", ls="--", lw=1.0)
    axes[0].set_ylabel("friction peak k1 [-]")
    axes[1].set_ylabel("falling slope k2 [-]")
    axes[0].legend(fontsize="small")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    _time_axis(axes[1], zone)
    axes[0].set_title("The squeal model's creep curves fitted to the measured squeal (dashed: configured)",
                      fontsize="medium")
    return fig


def speeds(speed_mps: np.ndarray, advisory) -> Figure:
    """Speed distributions in km/h, shares of train passes: the whole history, the advisory's recent
    passes and its advised distribution (every class; the plan is per class)."""
    fig, ax = plt.subplots(figsize=(8.0, 4.2), constrained_layout=True)
    if advisory is not None and len(advisory.speed_bin_centres_mps):
        c = KMH_PER_MPS * np.asarray(advisory.speed_bin_centres_mps)
        width = float(np.min(np.diff(c))) if len(c) > 1 else 2.0
        ax.bar(c - width / 4, advisory.current_probability, width / 2, label="recent passes")
        ax.bar(c + width / 4, advisory.recommended_probability, width / 2,
               label=f"advised (peak growth -{100 * advisory.peak_growth_reduction:.0f} %)")
        bins = np.append(c - width / 2, c[-1] + width / 2)
    else:
        bins = 30
    hist, edges = np.histogram(KMH_PER_MPS * speed_mps, bins=bins)
    ax.stairs(hist / max(hist.sum(), 1), edges, color="k", label="whole history")
    ax.set_xlabel("pass speed [km/h]")
    ax.set_ylabel("share of train passes [-]")
    ax.set_title("Speed distribution (every class; the advice keeps each class's mean speed)", fontsize="medium")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    return fig


def timeline(days: Mapping[str, np.ndarray], models: list[str], lim: Mapping[str, Any], zone: str) -> Figure:
    """Per local day: passes and squealing passes (bars), and the day's highest noise metric per model
    against the limit."""
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8.0, 5.6), constrained_layout=True)
    t = dates(days["day_ns"])
    width = np.timedelta64(20, "h")
    ax1.bar(t, days["passes"], width, align="edge", color="lightgrey", label="passes")
    ax1.bar(t, days["squealing"], width, align="edge", color="tab:red",
            label=f"squealing (risk {lim['squeal_min_risk']} or above)")
    ax1.set_ylabel("train passes per day [-]")
    ax1.legend(fontsize="small")
    ax1.grid(True, alpha=0.3)
    for j, model in enumerate(models):
        ax2.plot(t + width / 2, days[model], ".-", ms=3, color=f"C{j}", label=f"{model}, highest of the day")
    ax2.axhline(lim["limit_dba"], color="tab:red", lw=1.2, label=f"limit {lim['limit_dba']:g} dB(A)")
    ax2.set_ylabel(f"{METRIC_LABELS[lim['metric']]} [dB(A)]")
    ax2.legend(fontsize="small")
    ax2.grid(True, alpha=0.3)
    _time_axis(ax2, zone)
    ax1.set_title(f"Daily timeline ({zone} days)", fontsize="medium")
    return fig


def measured(t: Mapping[str, np.ndarray], models: list[str], residual_model: str, zone: str) -> Figure:
    """Measured against predicted LpAeq,Tp per pass for each model (with the 1:1 line), and the
    residual at 500-2000 Hz per pass against time with the site's running baseline."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    m = np.asarray(t["measured_lpaeq_tp_dba"], float)
    for model in models:
        predicted = m - np.asarray(t[f"{model}_residual_lpaeq_dba"], float)
        a.scatter(predicted, m, s=5, alpha=0.5, label=model)
    lo, hi = np.nanmin(m) - 2, np.nanmax(m) + 2
    a.plot([lo, hi], [lo, hi], "k--", lw=0.8, label="measured = predicted")
    a.set(xlabel="predicted LpAeq,Tp [dB(A)]", ylabel="measured LpAeq,Tp [dB(A)]", title="Measured against predicted")
    a.legend(fontsize=8)
    ok = np.isfinite(np.asarray(t[f"{residual_model}_residual_mid_db"], float))
    when = dates(np.asarray(t["stamp_ns"])[ok])
    b.scatter(when, np.asarray(t[f"{residual_model}_residual_mid_db"], float)[ok], s=4, alpha=0.5,
              label=f"{residual_model}, per pass")
    b.plot(when, np.asarray(t[f"{residual_model}_baseline_mid_db"], float)[ok], "k-", lw=1.2,
           label="the site's baseline (running median)")
    b.set(ylabel="measured minus predicted, 500-2000 Hz [dB]", title="Residual and baseline")
    b.legend(fontsize=8)
    _time_axis(b, zone)
    fig.tight_layout()
    return fig
