"""rail-monitor predict squeal: squeal amplitude and level for a crabbing velocity, or a sweep."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from rail_monitor.cli.common import add_site_option, print_json, site_values

# option, SquealCase field, unit
OVERRIDES = {"mass_kg": ("--mass", "kg"), "damping_nspm": ("--damping", "N s/m"),
             "stiffness_npm": ("--stiffness", "N/m"), "k1": ("--k1", "-"), "k2": ("--k2", "-"),
             "k3_n": ("--k3", "N")}


def add_parser(models: argparse._SubParsersAction) -> None:
    from rail_monitor.core.passes import FRICTION_BY_NAME
    from rail_monitor.models.squeal import K3_CONVENTIONS

    q = models.add_parser("squeal", help="squeal amplitude and level for a crabbing velocity, or a sweep")
    q.add_argument("--rig", action="store_true", help="the UQ paper's two-disc rig (Figure 5) instead of a site")
    q.add_argument("--history", help="pass history (bag folder, .mcap, .db3 or .csv): a table per friction state "
                   "(creep curve, unstable share, onset, mean level, friction-modifier cut) instead of one case")
    q.add_argument("--fit", action="store_true", help="with --history: each friction state's creep curve "
                   "re-fitted from the history's measured squeal (P10/P50/P90), with the squeal share measured, "
                   "by the configured curve and by the fitted one")
    q.add_argument("--measured", help="with --fit: measured pass-bys (a station CSV or a bag; default: the "
                   "history bag's own)")
    q.add_argument("--occurrence-only", action="store_true", help="with --fit: leave the measured tone levels out")
    add_site_option(q)
    q.add_argument("--vehicle-class", help="vehicle class of the site (default: its first)")
    q.add_argument("--friction", default="dry", choices=tuple(FRICTION_BY_NAME), help="friction state")
    q.add_argument("--speed", type=float, help="rolling speed V0 [m/s] (default: the class's mean)")
    q.add_argument("--load", type=float, help="wheel load W [N] (default: the class's nominal)")
    g = q.add_mutually_exclusive_group()
    g.add_argument("--aoa-mrad", type=float, help="angle of attack [mrad] (default 10)")
    g.add_argument("--crabbing", type=float, help="crabbing velocity Vc [m/s]")
    g.add_argument("--sweep", type=float, nargs=3, metavar=("VC_START", "VC_STOP", "N"),
                   help="sweep the crabbing velocity [m/s]")
    q.add_argument("--k3-convention", choices=K3_CONVENTIONS,
                   help="how k3 follows from Kalker's C22 (default: the site's contact.k3_convention)")
    for dest, (flag, unit) in OVERRIDES.items():
        q.add_argument(flag, dest=dest, type=float, help=f"override [{unit}]")
    q.add_argument("--reference", type=float, help="A w_ref of the relative level [m/s] (default: the largest A w)")
    q.add_argument("--ode", action="store_true", help="also integrate the ODE for every row (about 1 s each)")
    q.add_argument("--json", action="store_true", help="print JSON instead of a table")
    q.add_argument("--plot", help="save amplitude and relative level against Vc to this PNG")
    q.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    import dataclasses

    from rail_monitor.alerts.config import RISK_NAMES
    from rail_monitor.models.squeal import REGIME_NAMES
    from rail_monitor.squeal.config import squeal_config
    from rail_monitor.whatif.squeal import crabbing_velocities, squeal_case, sweep

    if ns.history:
        return _friction_table(ns)
    overrides = {k: getattr(ns, k) for k in OVERRIDES if getattr(ns, k) is not None}
    values = None if ns.rig else site_values(ns.site)
    case, where = squeal_case(values, ns.vehicle_class, ns.friction, ns.speed, ns.load, ns.k3_convention, **overrides)
    vc = crabbing_velocities(case, ns.sweep, ns.crabbing, ns.aoa_mrad)
    cfg = None if values is None else squeal_config(values)
    rows = sweep(case, vc, reference_mps=ns.reference, ode=ns.ode, cfg=cfg)
    site_level = "level_dba" in rows
    if ns.json:
        print_json({"case": dataclasses.asdict(case), "where": where,
                    "rows": [{**{k: v[i] for k, v in rows.items()}, "regime_name": REGIME_NAMES[int(rows["regime"][i])],
                              **({"risk_name": RISK_NAMES[int(rows["risk"][i])]} if site_level else {})}
                             for i in range(len(vc))]})
    else:
        print(f"# {where}: V0 {case.speed_mps:g} m/s, W {case.load_n:g} N, m {case.mass_kg:g} kg, "
              f"c {case.damping_nspm:g} N s/m, k {case.stiffness_npm:g} N/m, k1 {case.k1:g}, k2 {case.k2:g}, "
              f"k3 {case.k3_n:.4g} N, u_s {rows['critical_slip_velocity_mps'][0]:.4g} m/s")
        if site_level:
            print(f"# level at the site's receiver, {rows['frequency_hz'][0]:.0f} Hz mode; risk from the site's "
                  "dB(A) limits (squeal.risk_medium_dba, squeal.risk_high_dba); '-': no squeal")
        head = f"{'Vc [m/s]':>9} {'AoA [mrad]':>10} {'A w [m/s]':>10} {'rel [dB]':>9} {'regime':<26}"
        print(head + (f" {'level [dB(A)]':>13} {'risk':<6}" if site_level else "")
              + (f" {'ODE A w':>9}" if ns.ode else ""))
        for i in range(len(vc)):
            line = (f"{vc[i]:9.4f} {rows['angle_of_attack_mrad'][i]:10.2f} {rows['velocity_amplitude_mps'][i]:10.4f} "
                    f"{rows['relative_level_db'][i]:9.2f} {REGIME_NAMES[int(rows['regime'][i])]:<26}")
            if site_level:
                level = rows["level_dba"][i]
                line += f" {level:13.1f}" if np.isfinite(level) else f" {'-':>13}"
                line += f" {RISK_NAMES[int(rows['risk'][i])]:<6}"
            print(line + (f" {rows['ode_amplitude_mps'][i]:9.4f}" if ns.ode else ""))
    if ns.plot:
        from rail_monitor.whatif.plots import squeal_sweep

        print(f"plot: {squeal_sweep(rows, ns.plot, title=where)}", file=sys.stderr)
    return 0


def _friction_table(ns: argparse.Namespace) -> int:
    from pathlib import Path

    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.core.errors import RailMonitorError
    from rail_monitor.whatif.squeal import friction_states

    if ns.rig:
        raise RailMonitorError("--history is a site's: leave out --rig")
    if ns.fit:
        return _fit_table(ns)
    rows = friction_states(site_values(ns.site), read_passes(Path(ns.history)))
    if ns.json:
        print_json({"history": ns.history, "friction_states": rows})
        return 0
    print(f"{'friction state':<18} {'k1':>5} {'k2':>8} {'passes':>7} {'unstable':>9} {'onset':>10} "
          f"{'mean level':>11} {'FM cut':>8}")
    for r in rows:
        level, cut = r["mean_level_dba"], r["friction_modifier_cut_dba"]
        print(f"{r['friction_state']:<18} {r['k1']:5.2f} {r['k2']:8.4f} {r['passes']:7d} "
              f"{100 * r['unstable_share']:8.1f}% {r['onset_mrad']:5.2f} mrad "
              + (f"{level:6.1f} dB(A)" if np.isfinite(level) else f"{'-':>11}")
              + (f" {cut:5.1f} dB" if np.isfinite(cut) else f" {'-':>8}"))
    return 0


def _fit_table(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.reader import read_history_inputs, read_passes
    from rail_monitor.core.errors import RailMonitorError
    from rail_monitor.whatif.squeal_fit import fit_squeal

    _, measured = read_history_inputs(ns.history, ns.measured)
    if not measured:
        raise RailMonitorError(f"{ns.history}: no measured pass-bys to fit on (give --measured, a station's CSV "
                               "or bag)")
    _, rows = fit_squeal(site_values(ns.site), read_passes(ns.history), measured, levels=not ns.occurrence_only)
    if ns.json:
        print_json({"history": ns.history, "levels": not ns.occurrence_only, "friction_states": rows})
        return 0
    print("# creep curves re-fitted from measured squeal" + (" occurrence" if ns.occurrence_only else
                                                               " occurrence and tone levels")
          + "; shares of the measured passes that squeal")
    print(f"{'friction state':<18} {'k1 conf.':>8} {'k1 P10/P50/P90':>20} {'k2 conf.':>9} {'k2 P10/P50/P90':>26} "
          f"{'passes':>7} {'measured':>9} {'conf.':>7} {'fitted':>7}")
    for r in rows:
        k1, k2 = r["k1_p10_p50_p90"], r["k2_p10_p50_p90"]
        print(f"{r['friction_state']:<18} {r['k1']:8.3f} {k1[0]:6.3f}/{k1[1]:6.3f}/{k1[2]:6.3f} {r['k2']:9.4f} "
              f"{k2[0]:8.4f}/{k2[1]:8.4f}/{k2[2]:8.4f} {r['passes']:7d} {100 * r['measured_share']:8.1f}% "
              f"{100 * r['configured_share']:6.1f}% {100 * r['fitted_share']:6.1f}%")
    return 0
