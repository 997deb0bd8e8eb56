"""rail-monitor predict noise: rolling-noise pass-by levels and spectra (CNOSSOS-EU and the
mechanics model), before and after roughness growth."""

from __future__ import annotations

import argparse
import sys

from rail_monitor.cli.common import add_site_option, print_json, site_values

# option dest -> the site parameter it overrides
OVERRIDES = {"noise_model": "noise.model", "rail_roughness": "noise.rail_roughness",
             "sleeper_type": "noise.sleeper_type", "interpolation": "noise.interpolation",
             "edition": "noise.cnossos_edition",
             "distance": "noise.receiver_distance_m", "pad_stiffness": "track.pad_stiffness_npm"}


def add_parser(models: argparse._SubParsersAction) -> None:
    from rail_monitor.models.cnossos_bands import INTERPOLATION_RULES
    from rail_monitor.models.cnossos_tables import EDITIONS
    from rail_monitor.models.cnossos_transfer import SLEEPER_TYPES
    from rail_monitor.noise.config import MODELS, ROUGHNESS_SOURCES

    r = models.add_parser("noise", help="rolling noise pass-by levels and spectra (CNOSSOS-EU and mechanics), "
                          "before and after roughness growth")
    add_site_option(r)
    r.add_argument("--vehicle-class", help="vehicle class (default: the site's first)")
    r.add_argument("--speed", type=float, nargs="+", help="train speeds [m/s] (default: the class's mean)")
    r.add_argument("--vehicles", type=int, help="vehicles in the train (default: the class's mean consist)")
    r.add_argument("--model", dest="noise_model", choices=(*MODELS, "both"),
                   help="source model (default: the site's noise.model)")
    r.add_argument("--rail-roughness", choices=tuple(s for s in ROUGHNESS_SOURCES if s != "measured"),
                   help="baseline rail roughness class (default: the site's)")
    r.add_argument("--sleeper-type", choices=SLEEPER_TYPES, help="CNOSSOS sleeper type (default: the site's)")
    r.add_argument("--pad-stiffness", type=float, help="rail pad stiffness [N/m] (track.pad_stiffness_npm)")
    r.add_argument("--interpolation", choices=INTERPOLATION_RULES,
                   help="wavelength-to-band interpolation rule (default: the site's)")
    r.add_argument("--edition", choices=EDITIONS, help="CNOSSOS-EU edition of Appendix G (default: the site's)")
    r.add_argument("--distance", type=float, help="receiver distance from the track centre [m]")
    r.add_argument("--growth-days", type=float, nargs="+",
                   help="also predict after this many days of corrugation growth from grinding (at the first speed)")
    r.add_argument("--passes-per-day", type=float, default=100.0, help="trains per day for --growth-days")
    r.add_argument("--json", action="store_true", help="print JSON (spectra and single numbers) instead of a table")
    r.add_argument("--plot", metavar="PNG", help="save A-weighted spectra at the speeds and after growth")
    r.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.whatif.noise import predict_noise, summary

    values = site_values(ns.site)
    values.update({key: getattr(ns, dest) for dest, key in OVERRIDES.items() if getattr(ns, dest) is not None})
    r = predict_noise(values, ns.vehicle_class, ns.speed, ns.vehicles, ns.growth_days or (), ns.passes_per_day)
    if ns.json:
        print_json(summary(r))
    else:
        _print_table(r)
    if ns.plot:
        _plot(r, ns.plot)
    return 0


def _print_table(r) -> None:
    from rail_monitor.noise.predict import INCREASE_REFERENCE

    print(f"# {r.where}")
    print(f"# since grinding: LpAeq,Tp minus {INCREASE_REFERENCE}")
    print(f"{'model':>9} {'days':>6} {'v [m/s]':>8} {'LpAeq,Tp':>9} {'LpAFmax':>8} {'TEL':>6} {'since grinding':>14}"
          "  components [dB(A)]")
    for (name, days), out in r.results.items():
        for i in range(len(r.speeds)):
            comps = ", ".join(f"{c} {x:.1f}" for c, x in zip(*out.components(i), strict=True))
            print(f"{name:>9} {days:6g} {r.speeds[i]:8.2f} {out.lpaeq_tp_dba[i]:9.1f} {out.lpafmax_dba[i]:8.1f} "
                  f"{out.tel_dba[i]:6.1f} {out.roughness_growth_increase_db[i]:14.1f}  {comps}")


def _plot(r, path: str) -> None:
    from rail_monitor.models.levels import a_weighted
    from rail_monitor.whatif.plots import noise_spectra

    model = r.model
    name = model.models[0]
    base = r.results[(name, 0.0)]
    panels = {f"{name}: speeds": {f"{v:g} m/s, {base.lpaeq_tp_dba[i]:.1f} dB(A)": a_weighted(base.lp_db[i], model.band)
                                  for i, v in enumerate(r.speeds)}}
    days_run = [days for (m, days) in r.results if m == name]
    if len(days_run) > 1:
        panels[f"{name}: after roughness growth at {r.speeds[0]:g} m/s, {r.passes_per_day:g} trains/day"] = {
            f"{days:g} days, {r.results[(name, days)].lpaeq_tp_dba[0]:.1f} dB(A)":
                a_weighted(r.results[(name, days)].lp_db[0], model.band) for days in days_run}
    print(f"plot: {noise_spectra(model.band_hz, panels, path, title=r.where)}", file=sys.stderr)
