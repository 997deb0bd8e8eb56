"""A recorded run's console summary and its report folder (written by
:mod:`rail_monitor.report.page`).

Reads what the graph (or batch mode) recorded: train_pass, noise/squeal, corrugation/state,
noise/rolling, alerts and speed_advisory, matched by message type, so any namespace works. The
site file supplies what a bag does not hold: the model curves (squeal against crabbing velocity,
spectra before and after growth) and the validation of the passes.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor.alerts.config import KIND_NAMES
from rail_monitor.alerts.manager import describe
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.passes import FRICTION_NAMES, PassTable, rejection_reasons, synthetic_passes
from rail_monitor.core.site import Site
from rail_monitor.core.text import printable
from rail_monitor.core.timeutil import NS_PER_DAY, format_iso_ns, format_local_ns
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.report.run_data import RunData


def summary_lines(run: RunData, cfg: SiteConfig, max_alerts: int = 12) -> list[str]:
    """The console summary of a run."""
    site = cfg.site
    p = run.passes
    reasons = rejection_reasons(p, site)
    lines = [f"site {site.site_id}: {len(p)} passes from {format_iso_ns(int(p.stamp_ns.min()))} to "
             f"{format_iso_ns(int(p.stamp_ns.max()))} ({np.ptp(p.stamp_ns) / NS_PER_DAY:.1f} days; "
             f"{format_local_ns(int(p.stamp_ns.min()), site.time_zone)} to "
             f"{format_local_ns(int(p.stamp_ns.max()), site.time_zone)} local)"]
    bad = Counter(r for r in reasons.tolist() if r)
    lines.append(f"processed {int((reasons == '').sum())}, rejected {sum(bad.values())}"
                 + "".join(f"; {n} {why}" for why, n in bad.most_common(3)))
    raised = [a for a in run.alerts if a.active]
    lines.append(f"alerts: {len(raised)} raised, {len(run.alerts) - len(raised)} cleared"
                 + (", by kind: " + ", ".join(f"{KIND_NAMES[k]} {n}" for k, n in
                                             sorted(Counter(a.kind for a in raised).items())) if raised else ""))
    lines += ["  " + describe(a) for a in run.alerts[:max_alerts]]
    if len(run.alerts) > max_alerts:
        lines.append(f"  ... and {len(run.alerts) - max_alerts} more (alerts topic, report page)")
    lines += _grinding_lines(run)
    if run.advisory is not None and len(run.advisory.vehicle_class):
        from rail_monitor.advice.plan import advice_of_message

        lines.append("speed advice (per class, at its recent mean speed):")
        lines += ["  " + line for line in advice_of_message(run.advisory).lines()]
    for model, nz in run.noise.items():
        top = np.argsort(-nz["lpaeq_tp_dba"], kind="stable")[:3]
        cls = dict(zip(p.train_id.tolist(), p.vehicle_class.tolist(), strict=True))
        lines.append(f"loudest passes ({model}, LpAeq,Tp / LpAFmax at the receiver):")
        lines += [f"  {format_iso_ns(int(nz['stamp_ns'][i]))}  {nz['train_id'][i]:12s} "
                  f"{cls.get(nz['train_id'][i], ''):8s}"
                  f" {nz['speed_mps'][i]:5.1f} m/s  {nz['lpaeq_tp_dba'][i]:5.1f} / {nz['lpafmax_dba'][i]:5.1f} dB(A)"
                  for i in top]
    lines += _limit_lines(run, cfg)
    risk = run.squeal.get("risk", np.zeros(0, int))
    if len(risk):
        counts = np.bincount(risk.astype(int), minlength=4)
        lines.append(f"squeal: {int((risk > 0).sum())} of {len(risk)} passes unstable; risk low {counts[1]}, "
                     f"medium {counts[2]}, high {counts[3]}; loudest {np.max(run.squeal['level_dba']):.1f} dB(A)")
    return lines


def _limit_lines(run: RunData, cfg: SiteConfig, shown: int = 5) -> list[str]:
    """Noise percentiles against the limit, and the loudest squealing trains."""
    from rail_monitor.report import tables
    from rail_monitor.report.run_tables import pass_table

    t = pass_table(run, cfg).as_dict()
    lim = tables.limits(cfg)
    lines = [f"noise against the limit ({n['model']}, {n['metric']}): P50 {n['P50 [dB(A)]']:.1f}, P95 "
             f"{n['P95 [dB(A)]']:.1f}, max {n['max [dB(A)]']:.1f} dB(A); limit {n['limit [dB(A)]']:g} dB(A), "
             f"{n['above limit [%]']:.1f} % of passes above"
             for n in tables.noise_percentiles(t, lim, list(run.noise))]
    trains = tables.squealing_trains(t, lim) if "squeal_risk" in t else []
    lines.append(f"squealing trains (risk {lim['squeal_min_risk']} or above): {len(trains)}"
                 + (f"; the loudest {min(shown, len(trains))} (all in the report's squealing_trains.csv):"
                    if trains else ""))
    lines += [f"  {r['time (local)']}  {printable(r['train_id']):14s} {printable(r['class']):8s} "
              f"{r['speed [km/h]']:5.1f} km/h  {r['angle of attack [mrad]']:5.1f} mrad  {r['friction']:18s} "
              f"{r['squeal level [dB(A)]']:5.1f} dB(A) {r['risk']}" for r in trains[:shown]]
    return lines


def _grinding_lines(run: RunData) -> list[str]:
    s = run.states
    if not s:
        return ["corrugation: no state recorded"]
    w = int(s["worst_band"][-1])
    amp, thr = s["amplitude_m"][-1, w], s["threshold_m"][-1, w]
    lam = s["wavelength_m"][w]
    days = float(s["days_to_threshold"][-1])
    due = int(s["grinding_due_time"][-1])
    when = format_iso_ns(due)[:10] if due else "beyond 2038"
    head = "GRINDING DUE" if s["grinding_due"][-1] else "grinding forecast"
    text = (f"{head}: worst band {1e3 * lam:.1f} mm at {1e6 * amp:.2f} µm r.m.s. of its {1e6 * thr:.2f} µm "
            f"threshold; reached in {days:.0f} days ({when}) at {s['passes_per_day'][-1]:.0f} passes/day"
            if np.isfinite(days) else f"{head}: no band grows towards its threshold")
    grindings = sorted(set(s["last_grinding_time"].tolist()) - {0})
    return [text] + ([f"grinding events: {', '.join(format_iso_ns(g)[:10] for g in grindings)}"] if grindings else [])


# -- report folder ------------------------------------------------------------------------------
def build_report(run: RunData, cfg: SiteConfig, out_dir: str | Path, site_text: str = "", listen: int = 3,
                 archive: str | Path | None = None) -> list[Path]:
    """Write the report folder (rail_monitor.report.page) into out_dir; returns the files
    written, index.html last. site_text names the site file used; listen: the loudest passes made
    audible (rail_monitor.report.listening), beside their recordings in a station's archive
    folder (default: the site's station.archive_folder, where it exists). A write that fails (a
    full disk, no permission) is one RailMonitorError naming the folder."""
    from rail_monitor.report.listening import listening
    from rail_monitor.report.page import write_report

    out = Path(out_dir)
    extra: dict[str, Any] = {}
    if run.noise:
        extra["before"], extra["after"] = _spectra(run, cfg)
    if len(run.squeal.get("risk", ())):
        extra["curves"] = _squeal_curves(run, cfg)
    if archive is None and cfg.values.get("station.archive_folder"):
        archive = cfg.values["station.archive_folder"]
    try:
        out.mkdir(parents=True, exist_ok=True)
        extra["listen"] = listening(run, cfg, out, listen, Path(archive) if archive and Path(archive).is_dir()
                                    else None)
        return write_report(run, cfg, out, extra, site_text)
    except OSError as exc:
        raise RailMonitorError(f"{out}: cannot write the report: {exc.strerror or exc}") from None


def _reference_pass(run: RunData, site: Site) -> PassTable:
    """The most common class at its median recorded speed, in the consist of its first pass."""
    names, counts = np.unique(run.passes.vehicle_class.astype(str), return_counts=True)
    cls = str(names[np.argmax(counts)])
    rows = run.passes.vehicle_class == cls
    return synthetic_passes(site, site.vehicle(cls), np.array([np.median(run.passes.speed_mps[rows])]),
                            int(run.passes.vehicle_count[np.flatnonzero(rows)[0]]))


def _spectra(run: RunData, cfg: SiteConfig) -> tuple[dict[str, Any], dict[str, Any]]:
    """A-weighted 1/3-octave spectra of the reference pass on the post-grinding and the final rail."""
    from rail_monitor.noise.predict import RollingNoiseModel
    from rail_monitor.noise.records import Corrugation

    ref = _reference_pass(run, cfg.site)
    model = RollingNoiseModel(cfg.site, cfg.noise)
    before: dict[str, Any] = {"label": f"{ref.vehicle_class[0]} at {ref.speed_mps[0]:.1f} m/s"}
    after: dict[str, Any] = {}
    s = run.states
    for name in model.models:
        if s:
            corr = Corrugation(s["wavelength_m"], s["amplitude_m"][-1], s["post_grinding_m"][-1])
            post = Corrugation(s["wavelength_m"], s["post_grinding_m"][-1], s["post_grinding_m"][-1])
            before[name] = model.predict(ref, name, post)
            after[name] = model.predict(ref, name, corr)
        else:
            before[name] = after[name] = model.predict(ref, name)
    return before, after


def _squeal_curves(run: RunData, site_cfg: SiteConfig) -> dict[str, Any]:
    """Amplitude against crabbing velocity for the reference pass, per friction state."""
    from rail_monitor.whatif.squeal import site_case, sweep

    site, cfg = site_cfg.site, site_cfg.squeal
    ref = _reference_pass(run, site)
    top = max(float(np.max(run.squeal["crabbing_velocity_mps"], initial=0.0)) * 1.1, 0.05)
    vc = np.linspace(0.0, top, 200)
    curves = {"label": f"{ref.vehicle_class[0]} at {ref.speed_mps[0]:.1f} m/s"}
    for state, name in FRICTION_NAMES.items():
        case = site_case(cfg, site, str(ref.vehicle_class[0]), state, float(ref.speed_mps[0]))
        curves[name] = sweep(case, vc)
    return curves
