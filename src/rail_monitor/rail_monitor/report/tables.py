"""The report's numbers: the grinding outlook, squeal and noise against the site's limits, per
vehicle class, per day, and the squealing trains (the friction modifier's in
:mod:`rail_monitor.report.friction_modifier`).

Every table is a list of rows (dicts, units in the keys), computed from the per-pass table of
:func:`rail_monitor.report.run_tables.pass_table` (one row per pass with every model output), so the
report, the export and the console agree by construction.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from typing import Any

import numpy as np

from rail_monitor.alerts.config import counts_as_squeal
from rail_monitor.core.timeutil import NS_PER_DAY, format_local_ns
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.report.run_data import RunData

PERCENTILES = (50, 90, 95, 99)
METRIC_LABELS = {"lpaeq_tp_dba": "LpAeq,Tp", "lpafmax_dba": "LpAFmax", "tel_dba": "TEL"}
FULL_FORECAST, BAND_ESTIMATE = "the model's forecast", "estimate from the band's fastest growth"
TOP_SQUEALERS = 20


def limits(site: SiteConfig) -> dict[str, Any]:
    """The site's alert limits the report compares with, and the squeal model's background [dB(A)]."""
    cfg = site.alerts
    return {"metric": cfg.noise_metric, "limit_dba": cfg.noise_limit_dba, "squeal_min_risk": cfg.squeal_min_risk,
            "lead_time_days": cfg.lead_time_days, "squeal_background_dba": site.squeal.background_level_dba}


def squealing(t: Mapping[str, np.ndarray], min_risk: str) -> np.ndarray:
    """Passes whose squeal risk counts as an occurrence (the alert's own rule)."""
    if "squeal_risk" not in t:
        return np.zeros(len(t["stamp_ns"]), bool)
    return counts_as_squeal(t["squeal_risk"], min_risk)


def processed(t: Mapping[str, np.ndarray]) -> np.ndarray:
    return t["status"] == "processed"


def finite_mean(x: np.ndarray) -> float:
    x = x[np.isfinite(x)]
    return float(x.mean()) if len(x) else float("nan")


def noise_percentiles(t: Mapping[str, np.ndarray], lim: Mapping[str, Any], models: list[str]) -> list[dict]:
    """Per model: percentiles of the alert's noise metric over processed passes, and the share above
    the limit."""
    rows, ok = [], processed(t)
    for model in models:
        x = t[f"{model}_{lim['metric']}"][ok]
        x = x[np.isfinite(x)]
        if not len(x):
            continue
        row = {"model": model, "metric": METRIC_LABELS[lim["metric"]], "passes": len(x)}
        row.update({f"P{p} [dB(A)]": float(np.percentile(x, p)) for p in PERCENTILES})
        row["max [dB(A)]"] = float(x.max())
        row["limit [dB(A)]"] = lim["limit_dba"]
        row["above limit [%]"] = 100.0 * float((x > lim["limit_dba"]).mean())
        rows.append(row)
    return rows


def by_class(t: Mapping[str, np.ndarray], lim: Mapping[str, Any], models: list[str]) -> list[dict]:
    """Per vehicle class: traffic, speed, squeal share and level, noise median and P95."""
    ok = processed(t)
    sq = squealing(t, lim["squeal_min_risk"])
    rows = []
    for cls in sorted(set(t["vehicle_class"][ok].tolist())):
        m = ok & (t["vehicle_class"] == cls)
        row = {"class": cls, "passes": int(m.sum()), "share [%]": 100.0 * m.sum() / max(ok.sum(), 1),
               "mean speed [km/h]": finite_mean(t["speed_kmh"][m]),
               "squealing [%]": 100.0 * (sq & m).sum() / max(m.sum(), 1),
               "squeal level, mean of squealing [dB(A)]": finite_mean(t["squeal_level_dba"][sq & m])
               if "squeal_level_dba" in t else float("nan")}
        for model in models:
            x = t[f"{model}_{lim['metric']}"][m]
            x = x[np.isfinite(x)]
            row[f"{model} P50 [dB(A)]"] = float(np.median(x)) if len(x) else float("nan")
            row[f"{model} P95 [dB(A)]"] = float(np.percentile(x, 95)) if len(x) else float("nan")
        rows.append(row)
    return rows


AOA_BANDS_MRAD = (0.0, 2.0, 4.0, 6.0, 8.0, 10.0, np.inf)  # the squeal table's angle-of-attack bands


def heard_flags(heard: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The station's squeal-flag column (empty text where a pass was not measured): which passes
    it measured, and which it flagged squealing."""
    measured = np.array([v != "" for v in heard], bool)
    return measured, np.array([bool(v) for v in heard], bool) & measured


def squeal_by_angle(t: Mapping[str, np.ndarray], lim: Mapping[str, Any]) -> list[dict]:
    """Squeal predicted and, where a station measured it, heard, per angle-of-attack band: the
    model against the site where it matters most (empty without measured passes)."""
    heard = t.get("measured_squeal_detected")
    if heard is None:
        return []
    measured, flags = heard_flags(heard)
    measured &= processed(t)
    sq = squealing(t, lim["squeal_min_risk"])
    aoa = np.abs(np.asarray(t["angle_of_attack_mrad"], float))
    rows = []
    for lo, hi in itertools.pairwise(AOA_BANDS_MRAD):
        m = measured & (aoa >= lo) & (aoa < hi)
        if m.any():
            rows.append({"angle of attack [mrad]": f"{lo:g}-{hi:g}" if np.isfinite(hi) else f">= {lo:g}",
                         "measured passes": int(m.sum()), "squealing, predicted [%]": 100.0 * sq[m].mean(),
                         "squealing, measured [%]": 100.0 * flags[m].mean()})
    return rows


def squeal_fits(fits: Mapping[str, Mapping[str, np.ndarray]], zone: str) -> list[dict]:
    """Each friction state's latest fit of the squeal model to the measured squeal: its configured
    curve and the posterior's P10/P50/P90 (empty without fits)."""
    rows = []
    for state, f in fits.items():
        k1, k2 = (" / ".join(f"{f[f'{k}_{p}'][-1]:.4g}" for p in ("p10", "p50", "p90")) for k in ("k1", "k2"))
        passes = int(f["measured_passes"][-1])
        rows.append({"friction state": state, "fitted (local)": format_local_ns(int(f["stamp_ns"][-1]), zone),
                     "measured passes": passes,
                     "squealing, measured [%]": 100.0 * f["squealing_passes"][-1] / max(passes, 1),
                     "k1 configured": float(f["k1_configured"][-1]), "k1 P10 / P50 / P90": k1,
                     "k2 configured": float(f["k2_configured"][-1]), "k2 P10 / P50 / P90": k2,
                     **_share_checks(f)})
    return rows


def _share_checks(f: Mapping[str, np.ndarray]) -> dict[str, str]:
    """A state's fit windows with measured passes: how many had their measured squeal share outside
    the share the model predicted before the fit (P10-P90), and the last one's."""
    n = np.asarray(f["window_passes"], float)
    judged = np.flatnonzero(n > 0)
    if not len(judged):
        return {"windows outside predicted P10-P90": "-", "last window: measured / predicted [%]": "-"}
    share = np.asarray(f["window_squealing"], float)[judged] / n[judged]
    lo, hi = (np.asarray(f[f"window_share_{p}"], float)[judged] for p in ("p10", "p90"))
    return {"windows outside predicted P10-P90": f"{int(((share < lo) | (share > hi)).sum())} of {len(judged)}",
            "last window: measured / predicted [%]": f"{100 * share[-1]:.1f} / {100 * lo[-1]:.1f}-{100 * hi[-1]:.1f}"}


def repeat_squealers(alerts: list, zone: str) -> list[dict]:
    """The vehicles (or trains) the repeat-squealer alert named, the latest first."""
    from rail_monitor.alerts.config import KIND_SQUEAL_OFFENDER

    named = [a for a in alerts if a.kind == KIND_SQUEAL_OFFENDER and a.active]
    return [{"vehicle or train": a.key, "named (local)": format_local_ns(a.stamp_ns, zone), "why": a.summary}
            for a in sorted(named, key=lambda a: -a.stamp_ns)]


def squealing_trains(t: Mapping[str, np.ndarray], lim: Mapping[str, Any]) -> list[dict]:
    """Every squealing pass, loudest first."""
    sq = squealing(t, lim["squeal_min_risk"]) & processed(t)
    idx = np.flatnonzero(sq)
    idx = idx[np.argsort(-t["squeal_level_dba"][idx], kind="stable")]
    return [{"train_id": t["train_id"][i], "time (local)": t["time_local"][i], "class": t["vehicle_class"][i],
             "speed [km/h]": float(t["speed_kmh"][i]), "angle of attack [mrad]": float(t["angle_of_attack_mrad"][i]),
             "friction": t["friction_state"][i], "squeal level [dB(A)]": float(t["squeal_level_dba"][i]),
             "risk": t["squeal_risk"][i], "regime": t["squeal_regime"][i]} for i in idx]


def daily(t: Mapping[str, np.ndarray], lim: Mapping[str, Any], models: list[str], zone: str) -> dict[str, np.ndarray]:
    """Per local calendar day (the site's zone, daylight saving included): its start [ns], passes,
    squealing passes, and the highest noise metric per model [dB(A)]."""
    import pandas as pd

    ok = processed(t)
    local = pd.to_datetime(t["stamp_ns"][ok], utc=True).tz_convert(zone).normalize()
    frame = pd.DataFrame({"day": local, "squealing": squealing(t, lim["squeal_min_risk"])[ok],
                          **{m: t[f"{m}_{lim['metric']}"][ok] for m in models}})
    g = frame.groupby("day", sort=True)
    out = {"day_ns": np.array([d.value for d in g.size().index], np.int64), "passes": g.size().to_numpy(),
           "squealing": g["squealing"].sum().to_numpy()}
    out.update({m: g[m].max().to_numpy() for m in models})
    return out


def grinding_outlook(run: RunData, t: Mapping[str, np.ndarray], zone: str) -> list[dict]:
    """Per band, nearest its threshold first: r.m.s. now, threshold, and the forecast days and date at
    the recent traffic, with an interval from the spread of weekly traffic (10th-90th percentile of
    passes per day over the history). The worst band's days are the model's own forecast (the
    energy sum of its components); other bands use their largest growth rate."""
    s = run.states
    if not s:
        return []
    amp, thr = s["amplitude_m"][-1], s["threshold_m"][-1]
    growth = s["growth_per_axle_pass"][-1] if "growth_per_axle_pass" in s else np.full(len(amp), np.nan)
    axles = float(s["axle_pass_count"][-1]) / max(float(s["pass_count"][-1]), 1.0)
    rate = float(s["passes_per_day"][-1])
    low, high = weekly_rate_spread(t)
    newest = int(s["stamp"][-1])
    worst = int(s["worst_band"][-1])
    rows = []
    for b in np.argsort(-(amp / thr)):
        with np.errstate(divide="ignore", invalid="ignore"):
            passes = np.log(thr[b] / amp[b]) / growth[b] / axles if growth[b] > 0 else np.inf
        passes = max(passes, 0.0)
        if b == worst:
            passes = float(s["passes_to_threshold"][-1])
        days = passes / rate if rate > 0 else np.inf
        row = {"band [mm]": 1e3 * float(s["wavelength_m"][b]), "r.m.s. now [µm]": 1e6 * float(amp[b]),
               "threshold [µm]": 1e6 * float(thr[b]), "of threshold [%]": 100.0 * float(amp[b] / thr[b]),
               "days": days, "date": _date(newest, days, zone),
               "date range (traffic P90-P10)": f"{_date(newest, passes / high, zone)} to "
                                               f"{_date(newest, passes / low, zone)}" if low > 0 else "",
               "forecast": FULL_FORECAST if b == worst else BAND_ESTIMATE}
        rows.append(row)
    return rows


def weekly_rate_spread(t: Mapping[str, np.ndarray]) -> tuple[float, float]:
    """10th and 90th percentiles of passes per day over whole weeks of the history (NaN under 2 weeks)."""
    ok = processed(t)
    stamps = t["stamp_ns"][ok]
    if len(stamps) < 2:
        return float("nan"), float("nan")
    week = (stamps - stamps.min()) // (7 * NS_PER_DAY)
    full = np.bincount(week)[:-1] / 7.0  # the last week is partial
    if len(full) < 2:
        return float("nan"), float("nan")
    return float(np.percentile(full, 10)), float(np.percentile(full, 90))


def _date(newest_ns: int, days: float, zone: str) -> str:
    if not np.isfinite(days) or days > 3650:
        return "not within 10 years"
    return format_local_ns(newest_ns + int(days * NS_PER_DAY), zone)[:10]


def speed_advice(run: Any) -> list[dict]:
    """The last speed advisory's plan: a row per class and band, with the class's noise and squeal
    consequences (empty without an advisory)."""
    if run.advisory is None or not len(run.advisory.vehicle_class):
        return []
    from rail_monitor.advice.plan import advice_of_message

    a = advice_of_message(run.advisory)
    rows = []
    for c, name in enumerate(a.vehicle_class):
        change = a.noise_change(c)
        for i in (i for i, n in enumerate(a.band_vehicle_class) if n == name):
            rows.append({"class": name, "band [km/h]": a.band_label(i), "recent [%]": 100.0 * a.band_current_share[i],
                         "advised [%]": 100.0 * a.band_recommended_share[i],
                         **{f"noise change {m} [dB(A)]": float(change[j]) for j, m in enumerate(a.noise_model)},
                         "squealing recent [%]": 100.0 * a.class_squeal_share_current[c],
                         "squealing advised [%]": 100.0 * a.class_squeal_share_recommended[c]})
    return rows


def repeat_offenders(t: Mapping[str, np.ndarray], site: SiteConfig, zone: str) -> list[dict]:
    """The vehicles (or trains) whose measured passes scored as a wheel-defect suspect
    (alerts.wheel_defect_*; rail_monitor.alerts.manager.wheel_defect_score), most often flagged
    first."""
    cfg = site.alerts
    model = cfg.residual_model
    if f"{model}_excess_mid_db" not in t:
        return []
    excess = np.asarray(t[f"{model}_excess_mid_db"], float)
    loud = np.asarray(t[f"{model}_loudest_vehicle_excess_db"], float)
    named = np.array([bool(v) for v in t[f"{model}_loudest_vehicle_id"]]) & (loud >= cfg.wheel_defect_vehicle_db)
    score = np.fmax(excess, np.where(named, loud, np.nan))
    rows: dict[str, dict] = {}
    for i in np.flatnonzero(score >= cfg.wheel_defect_raise_db).tolist():
        key = f"vehicle {t[f'{model}_loudest_vehicle_id'][i]}" if named[i] else f"train {t['train_id'][i]}"
        row = rows.setdefault(key, {"vehicle or train": key, "passes flagged": 0, "largest score [dB]": -np.inf})
        row["passes flagged"] += 1
        row["largest score [dB]"] = round(max(row["largest score [dB]"], float(score[i])), 1)
        row["last flagged (local)"] = format_local_ns(int(t["stamp_ns"][i]), zone)
        row["last train"] = t["train_id"][i]
    return sorted(rows.values(), key=lambda r: (-r["passes flagged"], -r["largest score [dB]"]))
