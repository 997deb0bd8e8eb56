"""What-if corrugation: the growth, forecast and advice for a history or a given speed distribution,
as ``rail-monitor predict corrugation`` reports them (callable from Python too)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rail_monitor.advice import growth as adv
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.passes import FRICTION_BY_NAME, PassTable, rejection_reasons, with_class_defaults
from rail_monitor.core.site import site_from_values
from rail_monitor.core.timeutil import format_iso_ns
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Evaluation, Forecast, ForecastInterval
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.engine.corrugation_site import advance_with_events


@dataclass
class CorrugationWhatIf:
    """A what-if's inputs and results (units as in rail_msgs/CorrugationState and SpeedAdvisory)."""

    where: str                      # what was evaluated, for people
    estimator: CorrugationEstimator  # the state evaluated against
    speeds: np.ndarray              # [m/s]
    weights: np.ndarray             # relative weights of the speeds [-]
    friction_state: int             # 0: the history's mix
    vehicle_class: str | None       # the kernel's class without a history (None: the site's traffic mix)
    axles_per_train: float          # of the forecast [-]
    evaluation: Evaluation
    forecast: Forecast
    advice: Any                     # rail_monitor.advice.plan.SpeedAdvice, or None
    interval: ForecastInterval | None = None  # P10/P50/P90 of the history's forecast (None without one)
    events: int = 0                           # surveys and grinding events given with the history
    events_refused: dict[str, int] = field(default_factory=dict)
    explained: Any = None           # rail_monitor.advice.explain.AdviceExplained with the advice


def speed_distribution(mean_mps: float, cv: float) -> tuple[np.ndarray, np.ndarray]:
    """A normal distribution of speeds over +-3 sd on 121 points (speeds [m/s], weights), or the
    mean alone when cv = 0."""
    if cv <= 0:
        return np.array([mean_mps]), np.ones(1)
    speeds = mean_mps * (1 + cv * np.linspace(-3, 3, 121))
    return speeds, np.exp(-0.5 * ((speeds - mean_mps) / (mean_mps * cv)) ** 2)


def predict_corrugation(values: Mapping[str, Any], history: PassTable | None = None, history_name: str = "",
                        speeds: np.ndarray | None = None, weights: np.ndarray | None = None,
                        vehicle_class: str | None = None, speed_mean_mps: float | None = None,
                        speed_cv: float | None = None, friction: str | None = None,
                        passes_per_day: float | None = None, advise: bool = False,
                        events: Sequence[MaintenanceEvent] = ()) -> CorrugationWhatIf:
    """Evaluate a speed distribution for the site of the flat parameter values.

    With a history, the state, speeds (axle-weighted) and traffic come from it, with its surveys
    and grinding events (events) applied in stamp order, and the forecast has its P10/P50/P90
    interval; otherwise the
    post-grinding rail with the given speeds and weights, or a normal distribution of the
    class's mean and sd (overridden by speed_mean_mps [m/s] and speed_cv [-]), on dry rail
    unless friction names a state; the kernel and axles per train are then vehicle_class's when
    given, else the site's traffic mix and its traffic-weighted axles per train. The advice of a
    bare distribution is the history's advice on passes standing for it (distribution_passes:
    vehicle_class, or the site's first class). RailMonitorError for unusable inputs.
    """
    site = site_from_values(values)
    est = CorrugationEstimator(site, corrugation_config(values))
    state = FRICTION_BY_NAME[friction] if friction else 0
    kernel_class = None
    if history is not None:
        ok = rejection_reasons(history, site) == ""
        refused = dict(advance_with_events(est, with_class_defaults(history.take(ok), site), events).refused)
        where = f"site {site.site_id}, history {history_name} ({int(ok.sum())} passes, {int((~ok).sum())} rejected)"
        if not len(est.kept):
            raise RailMonitorError(f"{history_name}: no valid pass for site {site.site_id}")
        v, w = est.kept.speed, est.kept.axles.astype(float)
    else:
        kernel_class = vehicle_class
        cls = site.vehicle(vehicle_class or next(iter(site.vehicles)))
        if speeds is not None:
            v = np.asarray(speeds, float)
            w = np.asarray(weights, float) if weights is not None else np.ones_like(v)
            if w.shape != v.shape:
                raise RailMonitorError("--weights needs one weight per --speeds value")
        else:
            v, w = speed_distribution(speed_mean_mps or cls.speed_mean_mps,
                                      speed_cv if speed_cv is not None else cls.speed_sd_mps / cls.speed_mean_mps)
        state = state or FRICTION_BY_NAME["dry"]
        mix = f"class {vehicle_class}" if vehicle_class else "the site's traffic mix (" + ", ".join(
            f"{n} {100 * c.traffic_share:.0f} %" for n, c in site.vehicles.items()) + ")"
        where = f"site {site.site_id}, post-grinding rail, {friction or 'dry'}, kernel of {mix}"
    try:
        ev = adv.evaluate(est, v, w, state, passes_per_day or 0.0, kernel_class)
        advice = explained = None
        if advise:  # a bare distribution is advised as a history of its passes would be
            advice, explained = _advise(values, est if history is not None else distribution_estimator(
                values, kernel_class or next(iter(site.vehicles)), v, w, state))
    except ValueError as exc:
        raise RailMonitorError(str(exc)) from None
    axles = adv.axles_per_train(est, kernel_class)
    fc = est.forecast(adv.growth_at_speeds(est, v, state, kernel_class) @ (w / w.sum()), passes_per_day, axles)
    axles = axles or (est.traffic()[1] if len(est.kept) else site.mean_axles_per_train)
    if history is None:
        return CorrugationWhatIf(where, est, v, w, state, kernel_class, axles, ev, fc, advice, explained=explained)
    return CorrugationWhatIf(where, est, v, w, state, kernel_class, axles, ev, fc, advice, est.forecast_interval(),
                             len(events), refused, explained)


DISTRIBUTION_PASSES = 2000  # passes standing for a bare distribution (its quantiles)


def distribution_passes(values: Mapping[str, Any], vehicle_class: str, speeds: np.ndarray, weights: np.ndarray,
                        friction_state: int, n: int = DISTRIBUTION_PASSES) -> PassTable:
    """n passes of one class standing for a speed distribution: their speeds the distribution's
    quantiles at (i + 1/2) / n (the weighted speeds' step CDF, interpolated), in its mean consist,
    on one friction state, no angle of attack, 15 min apart from 2026-09-21 (valid, class defaults
    filled)."""
    site = site_from_values(values)
    cls = site.vehicle(vehicle_class)
    order = np.argsort(speeds, kind="stable")
    v, w = np.asarray(speeds, float)[order], np.asarray(weights, float)[order]
    cdf = (np.cumsum(w) - 0.5 * w) / w.sum()
    q = np.interp((np.arange(n) + 0.5) / n, cdf, v)
    return with_class_defaults(PassTable(
        stamp_ns=(1_790_000_000 + np.arange(n) * 900).astype(np.int64) * 10**9, train_id=[f"D{i}" for i in range(n)],
        vehicle_class=[vehicle_class] * n, vehicle_count=[max(round(cls.mean_vehicles), 1)] * n, axle_count=[0] * n,
        speed_mps=q, angle_of_attack_rad=[0.0] * n, wheel_load_n=[0.0] * n,
        friction_state=np.full(n, friction_state), train_length_m=[0.0] * n), site)


def distribution_estimator(values: Mapping[str, Any], vehicle_class: str, speeds: np.ndarray, weights: np.ndarray,
                           friction_state: int) -> CorrugationEstimator:
    """A post-grinding state advanced over the passes standing for a distribution (the advice's input)."""
    est = CorrugationEstimator(site_from_values(values), corrugation_config(values))
    est.advance(distribution_passes(values, vehicle_class, speeds, weights, friction_state))
    return est


def _advise(values: Mapping[str, Any], est: CorrugationEstimator) -> tuple[Any, Any]:
    """The speed advice on the history (noise and squeal of the site weighed), and what limits it."""
    from rail_monitor.advice.consequences import Consequences
    from rail_monitor.advice.explain import explain
    from rail_monitor.advice.plan import advise

    consequences = Consequences.of_values(est.site, values)
    return advise(est, consequences), explain(est, consequences)


def summary(r: CorrugationWhatIf) -> dict[str, Any]:
    """The what-if as plain data (JSON): single numbers, the advice, and a row per band."""
    est, ev, fc = r.estimator, r.evaluation, r.forecast
    out: dict[str, Any] = {
        "where": r.where, "peak_growth": ev.peak_growth, "peak_wavelength_m": ev.peak_wavelength_m,
        "worst_wavelength_m": float(est.bands[fc.worst_band]), "passes_to_threshold": fc.passes_to_threshold,
        "days_to_threshold": fc.days_to_threshold, "passes_per_day": fc.passes_per_day,
        "kernel_vehicle_class": r.vehicle_class, "axles_per_train": r.axles_per_train,
        "k_b_by_friction": est.k_b.tolist(), "k_b_p10_by_friction": est.k_b_p10.tolist(),
        "k_b_p90_by_friction": est.k_b_p90.tolist(), "calibration_surveys": est.calibration_surveys,
        "surveys_and_grinding": r.events, "surveys_and_grinding_refused": r.events_refused}
    iv = r.interval
    if iv is not None:
        out["forecast_interval"] = {
            "basis": "K_b posterior and each band's level uncertainty; traffic and friction mix of " + (
                "the same days a year earlier" if iv.basis == "season" else f"the recent {est.cfg.history_days:g} "
                "days (the history spans less than a year)"),
            "days_to_threshold_p10_p50_p90": iv.days.tolist(),
            "grinding_due_p10_p50_p90": [format_iso_ns(int(ns)) if ns else "never" for ns in iv.due_ns.tolist()]}
    if r.advice is not None:
        out["advice"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in vars(r.advice).items()}
        out["advice"]["summary"] = r.advice.lines()
        x = r.explained
        out["advice"]["limits"] = [vars(lim) for lim in x.relaxed]
        out["advice"]["timetable"] = {"length_m": x.length_m, "extra_running_time_s": x.extra_running_time_s,
                                      "worst_extra_running_time_s": x.worst_extra_running_time_s}
        out["advice"]["explanation"] = x.lines()
    out["bands"] = [{"wavelength_m": float(est.bands[i]), "growth_per_axle_pass": float(ev.growth_per_axle_pass[i]),
                     "amplitude_m": float(est.amplitude[i]), "threshold_m": float(est.threshold[i]),
                     **({} if iv is None else {"days_to_threshold_p10_p50_p90": iv.band_days[:, i].tolist()})}
                    for i in range(len(est.bands))]
    return out


def receptance_curves(site: Any) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The site's track receptances [m/N] (continuous Timoshenko and Euler, discrete at mid-span
    and above a sleeper) and its first class's wheel, on 20 Hz-5 kHz [Hz]."""
    from rail_monitor.models import track as tr
    from rail_monitor.models import wheel_rail_noise as wrn

    f = np.geomspace(20.0, 5000.0, 600)
    mid, above = tr.discrete_receptance(f, site.track, position=np.array([0.5, 0.0])).T
    wheel = site.vehicle(next(iter(site.vehicles))).unsprung_mass_kg
    return f, {"continuous, Timoshenko": tr.continuous_receptance(f, site.track),
               "continuous, Euler": tr.continuous_receptance(f, site.track, "euler"),
               "discrete, mid-span": mid, "discrete, above a sleeper": above,
               f"wheel ({wheel:g} kg)": wrn.wheel_receptance(f, wheel)}
