"""rail-monitor predict corrugation: growth per wavelength band, time to the grinding threshold,
and speed advice, for a history or a speed distribution."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from rail_monitor.cli.common import add_site_option, print_json, site_values
from rail_monitor.core.errors import RailMonitorError


def add_parser(models: argparse._SubParsersAction) -> None:
    from rail_monitor.core.passes import FRICTION_BY_NAME

    c = models.add_parser("corrugation", help="corrugation growth per wavelength band, time to the grinding "
                          "threshold, and speed advice")
    add_site_option(c)
    g = c.add_mutually_exclusive_group()
    g.add_argument("--history", help="pass history (bag folder, .mcap, .db3 or .csv): state, speeds and traffic "
                   "from it")
    g.add_argument("--speeds", type=float, nargs="+", help="speed histogram bin centres [m/s]")
    c.add_argument("--weights", type=float, nargs="+", help="weights of --speeds (default: equal)")
    c.add_argument("--vehicle-class", help="vehicle class without --history: its speeds, kernel and axles per train "
                   "(default: the site's traffic mix, at the first class's speeds)")
    c.add_argument("--speed-mean", type=float, help="mean speed of a normal distribution [m/s] (default: the class's)")
    c.add_argument("--speed-cv", type=float, help="its coefficient of variation [-] (default: the class's sd/mean)")
    c.add_argument("--friction", choices=tuple(FRICTION_BY_NAME),
                   help="friction state (default: dry, or the history's mix)")
    c.add_argument("--passes-per-day", type=float, help="train passes per day (default: the history's)")
    c.add_argument("--advise", action="store_true", help="also propose speed bands per vehicle class at each "
                   "class's mean speed (noise and squeal not raised): from the history, or from passes standing for "
                   "the given distribution (--vehicle-class, else the site's first class)")
    c.add_argument("--json", action="store_true", help="print JSON instead of a table")
    c.add_argument("--plot-receptance", metavar="PNG", help="save the track and wheel receptances to this PNG")
    c.add_argument("--plot-growth", metavar="PNG", help="save growth against wavelength (current and advised)")
    c.add_argument("--plot-cost", metavar="PNG", help="with --advise: save the worst band's growth over axle passes, "
                   "ground at its threshold, and the cumulative grinding cost (economics.*), current and advised")
    c.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.whatif.corrugation import predict_corrugation, summary

    if ns.plot_cost and not ns.advise:
        raise RailMonitorError("--plot-cost compares current and advised speeds: give --advise too")
    values = site_values(ns.site)
    history, events = None, []
    if ns.history:
        from rail_monitor.bagio.reader import read_bag_events, read_passes

        history, events = read_passes(Path(ns.history)), read_bag_events(Path(ns.history))
    r = predict_corrugation(values, history, ns.history or "", ns.speeds, ns.weights, ns.vehicle_class,
                            ns.speed_mean, ns.speed_cv, ns.friction, ns.passes_per_day, ns.advise, events)
    data = summary(r)
    if ns.json:
        print_json(data)
    else:
        _print_table(r, data)
    if ns.plot_receptance:
        _plot_receptance(r, ns.plot_receptance)
    if ns.plot_growth:
        _plot_growth(r, ns.plot_growth)
    if ns.plot_cost:
        _plot_cost(r, values, ns.plot_cost)
    return 0


def _print_table(r, data: dict) -> None:
    est, ev, fc, advice = r.estimator, r.evaluation, r.forecast, r.advice
    print(f"# {r.where}; K_b {', '.join(f'{k:.3g}' for k in est.k_b)} (dry, wet, modifier, contaminated)")
    print(f"{'lambda [mm]':>11} {'g [1/axle]':>11} {'Z [um]':>8} {'limit [um]':>10}")
    for b in data["bands"]:
        print(f"{1e3 * b['wavelength_m']:11.1f} {b['growth_per_axle_pass']:11.3e} {1e6 * b['amplitude_m']:8.3f} "
              f"{1e6 * b['threshold_m']:10.3f}")
    print(f"peak g {ev.peak_growth:.3e} per axle pass at {1e3 * ev.peak_wavelength_m:.1f} mm; worst band "
          f"{1e3 * est.bands[fc.worst_band]:.1f} mm reaches its limit in {fc.passes_to_threshold:.4g} train passes"
          f" = {fc.days_to_threshold:.4g} days at {fc.passes_per_day:.4g} passes/day of {r.axles_per_train:.3g} axles")
    if r.interval is not None:
        iv = data["forecast_interval"]
        p10, p50, p90 = iv["days_to_threshold_p10_p50_p90"]
        print(f"first band at its limit in {p10:.4g} / {p50:.4g} / {p90:.4g} days (P10 / P50 / P90: "
              f"{' / '.join(d[:10] for d in iv['grinding_due_p10_p50_p90'])}) from {iv['basis']}")
        print(f"K_b P10-P90 {', '.join(f'{a:.3g}-{b:.3g}' for a, b in zip(est.k_b_p10, est.k_b_p90, strict=True))}"
              f" after {est.calibration_surveys} survey fit(s); {r.events} survey(s)/grinding(s) in the history, "
              f"{sum(r.events_refused.values())} refused")
    if advice is not None:
        print("advice:")
        for line in advice.lines() + r.explained.lines():
            print(f"  {line}")


def _plot_receptance(r, path: str) -> None:
    from rail_monitor.whatif.corrugation import receptance_curves
    from rail_monitor.whatif.plots import track_receptance

    site = r.estimator.site
    f, curves = receptance_curves(site)
    print(f"plot: {track_receptance(f, curves, path, title=f'track of {site.site_id}')}", file=sys.stderr)


def _plot_growth(r, path: str) -> None:
    from rail_monitor.advice.growth import evaluate
    from rail_monitor.whatif.plots import corrugation_growth

    curves = {"current speeds": r.evaluation.growth_per_axle_pass}
    if r.advice is not None:
        curves["advised speeds (every class's shares)"] = evaluate(
            r.estimator, r.advice.speed_bin_centres_mps, r.advice.recommended_probability,
            r.friction_state).growth_per_axle_pass
    print(f"plot: {corrugation_growth(r.estimator.bands, curves, path, title=r.where)}", file=sys.stderr)




CYCLES_SHOWN = 5  # the cost figure spans this many of the current speeds' grinding cycles


def _plot_cost(r, values: dict, path: str) -> None:
    from rail_monitor.economics.config import economics_config
    from rail_monitor.economics.cycles import sawtooth
    from rail_monitor.whatif.plots import grinding_cycles

    a = r.advice
    band = int(np.argmin(np.abs(r.estimator.bands - a.current_peak_wavelength_m)))
    post, thr = float(r.estimator.post_grinding[band]), float(r.estimator.threshold[band])
    span = (CYCLES_SHOWN + 0.5) * np.log(thr / post) / a.current_peak_growth if a.current_peak_growth > 0 else 1e6
    n = np.linspace(0.0, span, 2000)
    curves = {"current speeds": sawtooth(post, thr, a.current_peak_growth, n),
              f"advised speeds (x{a.grinding_interval_factor:.2f} interval)": sawtooth(post, thr,
                                                                                   a.recommended_peak_growth, n)}
    title = f"{r.where}; worst band {1e3 * r.estimator.bands[band]:.0f} mm"
    print(f"plot: {grinding_cycles(n, curves, thr, economics_config(values).visit(), path, title)}", file=sys.stderr)
