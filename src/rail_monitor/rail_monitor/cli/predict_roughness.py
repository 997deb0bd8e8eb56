"""rail-monitor predict roughness: the indirect rail roughness from a history's measured pass-bys."""

from __future__ import annotations

import argparse
from pathlib import Path

from rail_monitor.cli.common import add_site_option, print_json, site_values

LABEL = ("indirect rail roughness from measured pass-by noise and the model's transfer functions "
         "(in the spirit of CEN/TR 16891; not an EN 15610 measurement)")


def add_parser(models: argparse._SubParsersAction) -> None:
    r = models.add_parser("roughness", help="indirect rail roughness per wavelength band from measured pass-bys")
    r.add_argument("--history", required=True, help="pass history (bag folder, .mcap, .db3 or .csv); its "
                   "surveys, grinding and measured pass-bys are applied as batch applies them")
    r.add_argument("--measured", help="measured pass-bys: a noise station's CSV or a bag (default: the history's)")
    r.add_argument("--days", type=float, default=28.0, help="the recent window of measured passes [day]")
    add_site_option(r)
    r.add_argument("--json", action="store_true", help="print JSON instead of a table")
    r.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.reader import read_history_inputs, read_passes
    from rail_monitor.batch.run import run_models
    from rail_monitor.whatif.roughness import indirect_of_run

    values = site_values(ns.site)
    history = Path(ns.history)
    events, measured = read_history_inputs(history, ns.measured)
    result = run_models(read_passes(history), values, events=events, measurements=measured)
    ind = indirect_of_run(result, values, ns.days)
    bands = [{"wavelength_m": float(ind.wavelength_m[k]), "indirect_db": float(ind.level_db[k]),
              "sd_db": float(ind.sd_db[k]), "model_db": float(ind.model_db[k]),
              "indirect_rms_m": float(ind.amplitude_m[k]), "pass_bands": int(ind.passes[k]),
              "rail_share": float(ind.rail_share[k])} for k in range(len(ind.wavelength_m))]
    if ns.json:
        print_json({"what": LABEL, "window_days": ns.days, "measured_passes": len(measured), "bands": bands})
        return 0
    print(f"# {LABEL}; the last {ns.days:g} days; dB re 1 um")
    print(f"{'lambda [mm]':>11} {'indirect':>9} {'+-sd':>6} {'model':>7} {'pass-bands':>10} {'rail share':>10}")
    for b in bands:
        print(f"{1e3 * b['wavelength_m']:11.1f} {_cell(b['indirect_db'])} {_cell(b['sd_db'], 6)} "
              f"{b['model_db']:7.2f} {b['pass_bands']:10d} {b['rail_share']:10.2f}")
    return 0


def _cell(x: float, width: int = 9) -> str:
    """A level, or '-' where there is no estimate (NaN; print_json writes it as null)."""
    return f"{'-':>{width}}" if x != x else f"{x:{width}.2f}"
