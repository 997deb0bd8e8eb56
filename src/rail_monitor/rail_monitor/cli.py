"""rail-monitor: command-line front end (simulate, replay, record, monitor, demo, batch, report, info, predict).

Node options are generated from the same ParamSpecs the nodes declare, so --help shows every
unit, range and default; they become ``-p name:=value`` ROS arguments. Errors the user can act
on are one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import shutil
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rail_monitor.errors import RailMonitorError
from rail_monitor.params import ParamSpec

DEFAULT_SAMPLE = Path("bags/sample")


def _site_file(path: str | None) -> Path:
    if path:
        return Path(path)
    from ament_index_python.packages import get_package_share_directory

    return Path(get_package_share_directory("rail_monitor")) / "config" / "curve_250.yaml"


def _site_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--site", help="site parameter file (default: the shipped curve_250.yaml)")


def _add_specs(parser: argparse.ArgumentParser, specs: Sequence[ParamSpec], skip: Sequence[str] = ()) -> None:
    group = parser.add_argument_group("node parameters (ROS 2 parameter in brackets)")
    for s in specs:
        if s.name in skip:
            continue
        flag = "--" + s.name.replace("_", "-").replace(".", "-")
        extra = f" {s.range_text()}" if (s.low is not None or s.high is not None or s.choices) else ""
        kw: dict = {"dest": "p:" + s.name, "default": None, "metavar": s.kind.__name__.upper(),
                    "help": f"{s.description}{extra} default: {s.default!r} [{s.name}]"}
        if isinstance(s.default, list):
            kw["nargs"] = "*"
        if s.kind is bool:
            kw.update(action=argparse.BooleanOptionalAction, metavar=None)
        else:
            kw["type"] = s.kind
        group.add_argument(flag, **kw)


def _ros_args(ns: argparse.Namespace, site: Path | None, extra: dict[str, object]) -> list[str]:
    """argv for rclpy.init: the site file, the namespace, and -p for every option given."""
    values = {k[2:]: v for k, v in vars(ns).items() if k.startswith("p:") and v is not None}
    values.update({k: v for k, v in extra.items() if v is not None})
    args = ["rail-monitor", *getattr(ns, "ros_extra", []), "--ros-args"]
    if site is not None:
        args += ["--params-file", str(site)]
    if getattr(ns, "namespace", None):
        args += ["-r", f"__ns:=/{ns.namespace.strip('/')}"]
    for name, v in values.items():
        if isinstance(v, bool):
            text = "true" if v else "false"
        elif isinstance(v, list):
            text = "[" + ",".join(f"'{x}'" if isinstance(x, str) else repr(x) for x in v) + "]"
        elif isinstance(v, str):
            text = f"'{v}'" if v else "''"
        else:
            text = repr(v)
        args += ["-p", f"{name}:={text}"]
    return args


# -- subcommands -----------------------------------------------------------------------------
def cmd_simulate(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.csv_io import write_csv
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.simulator import simulate, simulator_config
    from rail_monitor.site import load_parameter_file, site_from_values

    values = load_parameter_file(_site_file(ns.site))
    if ns.days is not None:
        values["simulator.days"] = ns.days
    if ns.seed is not None:
        values["simulator.seed"] = ns.seed
    site = site_from_values(values)
    table = simulate(site, simulator_config(values))
    if not ns.out and not ns.csv:
        raise RailMonitorError("give --out BAG and/or --csv FILE")
    if ns.out:
        if ns.force and Path(ns.out).exists():
            shutil.rmtree(ns.out)
        write_passes_bag(table, ns.out, site.site_id)
        print(f"wrote {len(table)} passes to bag {ns.out}")
    if ns.csv:
        write_csv(table, ns.csv)
        print(f"wrote {len(table)} passes to {ns.csv}")
    return 0


def cmd_info(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.reader import bag_info, is_csv, read_passes
    from rail_monitor.passes import FRICTION_NAMES
    from rail_monitor.timeutil import NS_PER_S, format_iso_ns

    path = Path(ns.bag)
    if ns.salvage:
        table = read_passes(path, ns.topic, salvage=True)
        print(table.salvage.line(path))
    else:
        if not is_csv(path):
            info = bag_info(path)
            span = (info.end_ns - info.start_ns) / NS_PER_S
            print(f"bag:       {info.path} ({info.storage})")
            print(f"start:     {format_iso_ns(info.start_ns)}")
            print(f"duration:  {span:.1f} s ({span / 86400:.2f} days)")
            print(f"messages:  {info.message_count}")
            for t in info.topics:
                print(f"  {t.name:32s} {t.typename:40s} {t.count}")
            if not any(t.typename == "rail_msgs/msg/TrainPass" for t in info.topics):
                return 0
        table = read_passes(path, ns.topic)
    if len(table):
        days = max((table.stamp_ns.max() - table.stamp_ns.min()) / 86400e9, 1e-9)
        print(f"passes:    {len(table)} ({len(table) / days:.1f} per day)")
        print(f"speed:     mean {table.speed_mps.mean():.2f} m/s, sd {table.speed_mps.std():.2f} m/s, "
              f"range {table.speed_mps.min():.2f}-{table.speed_mps.max():.2f} m/s")
        print(f"AoA:       mean {1e3 * table.angle_of_attack_rad.mean():.2f} mrad, "
              f"95th percentile {1e3 * np.percentile(table.angle_of_attack_rad, 95):.2f} mrad")
        states, counts = np.unique(table.friction_state, return_counts=True)
        mix = zip(states, counts, strict=True)
        print("friction:  " + ", ".join(f"{FRICTION_NAMES.get(int(s), s)} {c}" for s, c in mix))
        classes, counts = np.unique(table.vehicle_class.astype(str), return_counts=True)
        print("classes:   " + ", ".join(f"{c} {n}" for c, n in zip(classes, counts, strict=True)))
    return 0


def cmd_replay(ns: argparse.Namespace) -> int:
    from rail_monitor.nodes.pass_replayer import main

    return main(_ros_args(ns, _site_file(ns.site) if ns.site else None, {"source": ns.source}))


def cmd_record(ns: argparse.Namespace) -> int:
    from rail_monitor.nodes.mcap_recorder import main

    return main(_ros_args(ns, None, {"output": ns.output}))


def _monitor(ns: argparse.Namespace, source: str, output: str | None) -> int:
    from rail_monitor.nodes.wayside_monitor import main

    if output:
        _fresh_output(Path(output), ns.overwrite)
    site = _site_file(ns.site)
    if not ns.namespace:
        from rail_monitor.site import load_parameter_file

        ns.namespace = str(load_parameter_file(site).get("site_id", ""))
    return main(_ros_args(ns, site, {"source": source, "output": output, "use_sim_time": True}))


def _fresh_output(path: Path, overwrite: bool) -> None:
    """Make room for an output folder: remove it with overwrite, else refuse to touch it."""
    if path.exists():
        if not overwrite:
            raise RailMonitorError(f"{path} exists; remove it or pass --overwrite")
        shutil.rmtree(path)


def cmd_monitor(ns: argparse.Namespace) -> int:
    return _monitor_and_report(ns, ns.source)


def cmd_demo(ns: argparse.Namespace) -> int:
    if not ns.source.exists():
        raise RailMonitorError(f"{ns.source} not found: run the demo from the repository's top folder")
    return _monitor_and_report(ns, str(ns.source))


def _monitor_and_report(ns: argparse.Namespace, source: str) -> int:
    output = ns.output or f"rail_monitor_{Path(source).stem}"
    rc = _monitor(ns, source, output)
    if rc == 0 and not getattr(ns, "no_report", False):
        _report(output, ns.site, ns.report)
    return rc


def _report_dir(bag: str, report: str | None) -> Path:
    return Path(report) if report else Path(f"{str(bag).rstrip('/')}_report")


def _report(bag: str, site: str | None, report: str | None) -> None:
    """Print the run summary and write the report folder."""
    from rail_monitor.report import build_report, load_run, summary_lines
    from rail_monitor.site import load_parameter_file

    values = load_parameter_file(_site_file(site))
    run = load_run(bag)
    print("\n".join(summary_lines(run, values)))
    files = build_report(run, values, _report_dir(bag, report))
    print(f"report: {files[-1]} ({len(files) - 1} plots)")


def cmd_report(ns: argparse.Namespace) -> int:
    _report(ns.bag, ns.site, ns.out)
    return 0


def cmd_batch(ns: argparse.Namespace) -> int:
    import time

    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.batch import run_models, write_bag
    from rail_monitor.site import load_parameter_file

    t0 = time.monotonic()
    values = load_parameter_file(_site_file(ns.site))
    passes = read_passes(ns.source, ns.topic, salvage=ns.salvage)
    if ns.salvage:
        print(passes.salvage.line(ns.source))
    out = Path(ns.output or f"{Path(ns.source).stem}_batch")
    _fresh_output(out, ns.overwrite)
    result = run_models(passes, values)
    t_models = time.monotonic() - t0
    write_bag(result, out, ns.namespace if ns.namespace is not None else str(values.get("site_id", "")))
    print(f"batch: {len(passes)} passes through the models in {t_models:.2f} s "
          f"({len(passes) / max(t_models, 1e-9):.0f} passes/s); recorded to {out} in "
          f"{time.monotonic() - t0 - t_models:.1f} s")
    if not ns.no_report:
        _report(str(out), ns.site, ns.report)
    return 0


_SALVAGE_HELP = ("read every complete chunk of an MCAP file cut off mid-write (a killed recorder, a full disk) "
                 "and say how many messages it recovered")

# predict squeal: option, SquealCase field, unit
_SQUEAL_OVERRIDES = {"mass_kg": ("--mass", "kg"), "damping_nspm": ("--damping", "N s/m"),
                     "stiffness_npm": ("--stiffness", "N/m"), "k1": ("--k1", "-"), "k2": ("--k2", "-"),
                     "k3_n": ("--k3", "N")}


def cmd_predict_squeal(ns: argparse.Namespace) -> int:
    import dataclasses
    import json

    from rail_monitor import squeal_risk
    from rail_monitor.models.squeal import REGIME_NAMES
    from rail_monitor.passes import FRICTION_BY_NAME
    from rail_monitor.site import load_parameter_file, site_from_values

    if ns.rig and ns.load:
        raise RailMonitorError("--load does not apply to --rig: the rig's k3 is for its 1000 N (Figure 5)")
    if ns.rig:
        case = squeal_risk.rig_case(ns.k3_convention or "kalker_unit")
        where = "seed rig (Figure 5)"
    else:
        values = load_parameter_file(_site_file(ns.site))
        if ns.k3_convention:
            values["squeal.k3_convention"] = ns.k3_convention
        site = site_from_values(values)
        cls = ns.vehicle_class or next(iter(site.vehicles))
        speed = ns.speed or site.vehicle(cls).speed_mean_mps
        case = squeal_risk.site_case(squeal_risk.squeal_config(values), site, cls, FRICTION_BY_NAME[ns.friction],
                                     speed, ns.load or 0.0)
        where = f"site {site.site_id}, class {cls}, {ns.friction}"
    overrides = {k: getattr(ns, k) for k in _SQUEAL_OVERRIDES if getattr(ns, k) is not None}
    if ns.speed:
        overrides["speed_mps"] = ns.speed
    case = dataclasses.replace(case, **overrides)
    if ns.sweep:
        start, stop, count = ns.sweep
        vc = np.linspace(start, stop, int(count))
    elif ns.crabbing is not None:
        vc = np.array([ns.crabbing])
    else:
        vc = np.array([case.speed_mps * np.sin(1e-3 * (ns.aoa_mrad if ns.aoa_mrad is not None else 10.0))])
    rows = squeal_risk.sweep(case, vc, reference_mps=ns.reference, ode=ns.ode)
    if ns.json:
        print(json.dumps({"case": dataclasses.asdict(case), "where": where,
                          "rows": [{k: (v[i].item() if np.isfinite(v[i]) else None) for k, v in rows.items()}
                                   for i in range(len(vc))]}, indent=1))
    else:
        print(f"# {where}: V0 {case.speed_mps:g} m/s, W {case.load_n:g} N, m {case.mass_kg:g} kg, "
              f"c {case.damping_nspm:g} N s/m, k {case.stiffness_npm:g} N/m, k1 {case.k1:g}, k2 {case.k2:g}, "
              f"k3 {case.k3_n:.4g} N, u_s {rows['critical_slip_velocity_mps'][0]:.4g} m/s")
        head = f"{'Vc [m/s]':>9} {'AoA [mrad]':>10} {'A w [m/s]':>10} {'rel [dB]':>9} {'regime':<16}"
        print(head + (f" {'ODE A w':>9}" if ns.ode else ""))
        for i in range(len(vc)):
            line = (f"{vc[i]:9.4f} {rows['angle_of_attack_mrad'][i]:10.2f} {rows['velocity_amplitude_mps'][i]:10.4f} "
                    f"{rows['relative_level_db'][i]:9.2f} {REGIME_NAMES[int(rows['regime'][i])]:<16}")
            print(line + (f" {rows['ode_amplitude_mps'][i]:9.4f}" if ns.ode else ""))
    if ns.plot:
        from rail_monitor.plots import squeal_sweep

        print(f"plot: {squeal_sweep(rows, ns.plot, title=where)}", file=sys.stderr)
    return 0


def cmd_predict_corrugation(ns: argparse.Namespace) -> int:
    import json

    from rail_monitor.corrugation_state import CorrugationEstimator, corrugation_config
    from rail_monitor.passes import FRICTION_BY_NAME, rejection_reasons, with_class_defaults
    from rail_monitor.site import load_parameter_file, site_from_values

    values = load_parameter_file(_site_file(ns.site))
    site = site_from_values(values)
    est = CorrugationEstimator(site, corrugation_config(values))
    friction = FRICTION_BY_NAME[ns.friction] if ns.friction else 0
    if ns.history:
        from rail_monitor.bagio.reader import read_passes

        table = read_passes(Path(ns.history))
        ok = rejection_reasons(table, site) == ""
        est.advance(with_class_defaults(table.take(ok), site))
        where = f"site {site.site_id}, history {ns.history} ({int(ok.sum())} passes, {int((~ok).sum())} rejected)"
        if not len(est.recent.stamp_ns):
            raise RailMonitorError(f"{ns.history}: no valid pass for site {site.site_id}")
        speeds, weights = est.recent.speed, est.recent.axles.astype(float)
    else:
        cls = site.vehicle(ns.vehicle_class or next(iter(site.vehicles)))
        if ns.speeds:
            speeds = np.asarray(ns.speeds, float)
            weights = np.asarray(ns.weights, float) if ns.weights else np.ones_like(speeds)
            if weights.shape != speeds.shape:
                raise RailMonitorError("--weights needs one weight per --speeds value")
        else:
            mean = ns.speed_mean or cls.speed_mean_mps
            cv = ns.speed_cv if ns.speed_cv is not None else cls.speed_sd_mps / cls.speed_mean_mps
            speeds = mean * (1 + cv * np.linspace(-3, 3, 121)) if cv > 0 else np.array([mean])
            weights = np.exp(-0.5 * ((speeds - mean) / (mean * cv)) ** 2) if cv > 0 else np.ones(1)
        friction = friction or FRICTION_BY_NAME["dry"]
        where = f"site {site.site_id}, post-grinding rail, {ns.friction or 'dry'}"
    try:
        ev = est.evaluate(speeds, weights, friction, ns.passes_per_day or 0.0)
        advice = est.advise(None if ns.history and not ns.friction else speeds, weights, friction) \
            if ns.advise else None
    except ValueError as exc:
        raise RailMonitorError(str(exc)) from None
    fc = est.forecast(est.growth_at_speeds(speeds, friction) @ (weights / weights.sum()), ns.passes_per_day)
    rows = [{"wavelength_m": float(est.bands[i]), "growth_per_axle_pass": float(ev.growth_per_axle_pass[i]),
             "amplitude_m": float(est.amplitude[i]), "threshold_m": float(est.threshold[i])}
            for i in range(len(est.bands))]
    summary = {"where": where, "peak_growth": ev.peak_growth, "peak_wavelength_m": ev.peak_wavelength_m,
               "worst_wavelength_m": float(est.bands[fc.worst_band]), "passes_to_threshold": fc.passes_to_threshold,
               "days_to_threshold": fc.days_to_threshold, "passes_per_day": fc.passes_per_day,
               "k_b_by_friction": est.k_b.tolist()}
    if advice is not None:
        summary["advice"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in vars(advice).items()}
    if ns.json:
        print(json.dumps({**summary, "bands": rows}, indent=1, default=lambda x: None))
    else:
        print(f"# {where}; K_b {', '.join(f'{k:.3g}' for k in est.k_b)} (dry, wet, modifier, contaminated)")
        print(f"{'lambda [mm]':>11} {'g [1/axle]':>11} {'Z [um]':>8} {'limit [um]':>10}")
        for r in rows:
            print(f"{1e3 * r['wavelength_m']:11.1f} {r['growth_per_axle_pass']:11.3e} {1e6 * r['amplitude_m']:8.3f} "
                  f"{1e6 * r['threshold_m']:10.3f}")
        print(f"peak g {ev.peak_growth:.3e} per axle pass at {1e3 * ev.peak_wavelength_m:.1f} mm; worst band "
              f"{1e3 * est.bands[fc.worst_band]:.1f} mm reaches its limit in {fc.passes_to_threshold:.4g} train passes"
              f" = {fc.days_to_threshold:.4g} days at {fc.passes_per_day:.4g} passes/day")
        if advice is not None:
            used = advice.recommended_probability > 1e-6
            mix = zip(advice.speed_bin_centres_mps[used], advice.recommended_probability[used], strict=True)
            factor = advice.grinding_interval_factor
            print(f"advice: same mean {advice.mean_speed_mps:.2f} m/s, speeds "
                  + ", ".join(f"{v:.2f} ({100 * p:.0f} %)" for v, p in mix)
                  + f"; peak growth -{100 * advice.peak_growth_reduction:.0f} %, grinding interval x{factor:.2f}, "
                  f"grinding cost -{100 * (1 - 1 / factor):.0f} %")
    if ns.plot_receptance:
        from rail_monitor.models import track as tr
        from rail_monitor.plots import track_receptance

        f = np.geomspace(20.0, 5000.0, 600)
        mid, above = tr.discrete_receptance(f, site.track, position=np.array([0.5, 0.0])).T
        curves = {"continuous, Timoshenko": tr.continuous_receptance(f, site.track),
                  "continuous, Euler": tr.continuous_receptance(f, site.track, "euler"),
                  "discrete, mid-span": mid, "discrete, above a sleeper": above,
                  f"wheel ({site.vehicle(next(iter(site.vehicles))).unsprung_mass_kg:g} kg)":
                      tr.wheel_receptance(f, site.vehicle(next(iter(site.vehicles))).unsprung_mass_kg)}
        print(f"plot: {track_receptance(f, curves, ns.plot_receptance, title=f'track of {site.site_id}')}",
              file=sys.stderr)
    if ns.plot_growth:
        from rail_monitor.plots import corrugation_growth

        curves = {"current speeds": ev.growth_per_axle_pass}
        if advice is not None:
            curves["advised speeds"] = est.evaluate(advice.speed_bin_centres_mps, advice.recommended_probability,
                                                    friction).growth_per_axle_pass
        print(f"plot: {corrugation_growth(est.bands, curves, ns.plot_growth, title=where)}", file=sys.stderr)
    return 0


def cmd_predict_noise(ns: argparse.Namespace) -> int:
    import json

    from rail_monitor.corrugation_state import CorrugationEstimator, corrugation_config
    from rail_monitor.models import corrugation as cg
    from rail_monitor.models.levels import a_weighted
    from rail_monitor.passes import FRICTION_BY_NAME, PassTable, with_class_defaults
    from rail_monitor.rolling_noise import Corrugation, RollingNoiseModel, noise_config
    from rail_monitor.site import load_parameter_file, site_from_values

    values = load_parameter_file(_site_file(ns.site))
    overrides = {"noise.model": ns.noise_model, "noise.rail_roughness": ns.rail_roughness,
                 "noise.sleeper_type": ns.sleeper_type, "noise.interpolation": ns.interpolation,
                 "noise.receiver_distance_m": ns.distance, "track.pad_stiffness_npm": ns.pad_stiffness}
    values.update({k: v for k, v in overrides.items() if v is not None})
    site = site_from_values(values)
    model = RollingNoiseModel(site, noise_config(values))
    cls = site.vehicle(ns.vehicle_class or next(iter(site.vehicles)))
    speeds = np.asarray(ns.speed or [cls.speed_mean_mps], float)
    if np.any(~np.isfinite(speeds) | (speeds <= 0) | (speeds > 120)):
        raise RailMonitorError("--speed values must be in (0, 120] m/s")
    vehicles = ns.vehicles or round((cls.vehicles_min + cls.vehicles_max) / 2)
    n = len(speeds)
    table = with_class_defaults(PassTable(
        stamp_ns=np.arange(1, n + 1), train_id=[f"speed {v:g}" for v in speeds], vehicle_class=[cls.name] * n,
        vehicle_count=[vehicles] * n, axle_count=[0] * n, speed_mps=speeds, angle_of_attack_rad=[0.0] * n,
        wheel_load_n=[0.0] * n, friction_state=[FRICTION_BY_NAME["dry"]] * n, train_length_m=[0.0] * n), site)

    # Roughness growth: the corrugation model's growth at the first speed, for each number of days.
    est = CorrugationEstimator(site, corrugation_config(values))
    per_axle = est.growth_at_speeds(speeds[:1], FRICTION_BY_NAME["dry"])[..., 0]
    axles_per_day = ns.passes_per_day * cls.mean_axles_per_train
    # Without --growth-days: the baseline rail; with it, day 0 is the rail just after grinding.
    states = {0.0: Corrugation(est.bands, est.grinding_amplitude, est.grinding_amplitude) if ns.growth_days else None}
    for days in ns.growth_days or []:
        amp = cg.band_amplitude(est.log_components + per_axle * axles_per_day * days)
        states[days] = Corrugation(est.bands, amp, est.grinding_amplitude)
    results = {(name, days): model.predict(table, name, state)
               for name in model.models for days, state in states.items()}
    where = (f"site {site.site_id}, {cls.name} ({cls.brake_type} brakes, {vehicles} vehicles), rail "
             f"{model.cfg['rail_roughness']}, {model.track_name}, receiver {model.receiver.distance_m:g} m / "
             f"{model.receiver.height_m:g} m")
    if ns.json:
        def row(out: dict, i: int) -> dict:
            keys = ("lpaeq_tp_dba", "lpafmax_dba", "tel_dba", "pass_by_time_s", "roughness_growth_increase_db")
            return {"speed_mps": float(speeds[i]), **{k: float(out[k][i]) for k in keys},
                    "components_lpaeq_dba": dict(zip(out["component_names"], out["component_lpaeq_dba"][i].tolist(),
                                                     strict=True)),
                    "lp_db": out["lp_db"][i].tolist(), "lw_db_per_m": out["lw_db"][i].tolist(),
                    "roughness_db": out["roughness_db"][i].tolist()}
        print(json.dumps({"where": where, "band_centre_hz": model.band_hz.tolist(), "results": [
            {"model": name, "growth_days": days, "passes": [row(out, i) for i in range(n)]}
            for (name, days), out in results.items()]}, indent=1))
    else:
        print(f"# {where}")
        print(f"{'model':>9} {'days':>6} {'v [m/s]':>8} {'LpAeq,Tp':>9} {'LpAFmax':>8} {'TEL':>6} {'growth':>7}"
              "  components [dB(A)]")
        for (name, days), out in results.items():
            for i in range(n):
                comps = ", ".join(f"{c} {x:.1f}" for c, x in zip(out["component_names"], out["component_lpaeq_dba"][i],
                                                                 strict=True))
                print(f"{name:>9} {days:6g} {speeds[i]:8.2f} {out['lpaeq_tp_dba'][i]:9.1f} "
                      f"{out['lpafmax_dba'][i]:8.1f} {out['tel_dba'][i]:6.1f} "
                      f"{out['roughness_growth_increase_db'][i]:7.1f}  {comps}")
    if ns.plot:
        from rail_monitor.plots import noise_spectra

        name = model.models[0]
        base = results[(name, 0.0)]
        def aw(lp: np.ndarray) -> np.ndarray:
            return a_weighted(lp, model.band)
        panels = {f"{name}: speeds": {f"{v:g} m/s, {base['lpaeq_tp_dba'][i]:.1f} dB(A)": aw(base["lp_db"][i])
                                      for i, v in enumerate(speeds)}}
        if len(states) > 1:
            panels[f"{name}: after roughness growth at {speeds[0]:g} m/s, {ns.passes_per_day:g} trains/day"] = {
                f"{days:g} days, {results[(name, days)]['lpaeq_tp_dba'][0]:.1f} dB(A)":
                    aw(results[(name, days)]["lp_db"][0]) for days in states}
        print(f"plot: {noise_spectra(model.band_hz, panels, ns.plot, title=where)}", file=sys.stderr)
    return 0


def build_parser() -> argparse.ArgumentParser:
    from rail_monitor.models.squeal import K3_CONVENTIONS
    from rail_monitor.nodes.mcap_recorder import RECORDER_SPECS
    from rail_monitor.nodes.pass_replayer import REPLAYER_SPECS
    from rail_monitor.nodes.pass_source import PUBLISH_SPECS
    from rail_monitor.nodes.wayside_monitor import MONITOR_SPECS
    from rail_monitor.passes import FRICTION_BY_NAME

    p = argparse.ArgumentParser(prog="rail-monitor", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("simulate", help="generate a seeded pass history for a site into a bag and/or CSV")
    _site_option(s)
    s.add_argument("--out", help="bag folder to create (MCAP)")
    s.add_argument("--csv", help="CSV file to write")
    s.add_argument("--days", type=float, help="override simulator.days [day]")
    s.add_argument("--seed", type=int, help="override simulator.seed [-]")
    s.add_argument("--force", action="store_true", help="replace an existing bag folder")
    s.set_defaults(func=cmd_simulate)

    s = sub.add_parser("info", help="summarise a bag or CSV: topics, counts, time span, pass statistics")
    s.add_argument("bag", help="bag folder, .mcap, .db3 or .csv")
    s.add_argument("--topic", help="TrainPass topic to summarise (default: the only one)")
    s.add_argument("--salvage", action="store_true", help=_SALVAGE_HELP)
    s.set_defaults(func=cmd_info)

    s = sub.add_parser("replay", help="run pass_replayer: publish a history on train_pass with /clock")
    s.add_argument("source", help="bag folder, .mcap, .db3 or .csv")
    s.add_argument("--site", help="site parameter file (for site_id)")
    s.add_argument("--namespace", help="site namespace for the topics, e.g. curve_250")
    _add_specs(s, PUBLISH_SPECS + REPLAYER_SPECS, skip=("source",))
    s.set_defaults(func=cmd_replay)

    s = sub.add_parser("record", help="run mcap_recorder until Ctrl-C or SIGTERM")
    s.add_argument("output", help="bag folder to create")
    s.add_argument("--namespace", help="site namespace (relative topic names resolve under it)")
    _add_specs(s, RECORDER_SPECS, skip=("output",))
    s.set_defaults(func=cmd_record)

    s = sub.add_parser("predict", help="run one model on physical inputs")
    models = s.add_subparsers(dest="model", required=True)
    q = models.add_parser("squeal", help="squeal amplitude and level for a crabbing velocity, or a sweep",
                          formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    q.add_argument("--rig", action="store_true", help="the seed's two-disc rig (Figure 5) instead of a site")
    _site_option(q)
    q.add_argument("--vehicle-class", help="vehicle class of the site (default: its first)")
    q.add_argument("--friction", default="dry", choices=tuple(FRICTION_BY_NAME))
    q.add_argument("--speed", type=float, help="rolling speed V0 [m/s] (default: the class's mean)")
    q.add_argument("--load", type=float, help="wheel load W [N] (default: the class's nominal)")
    g = q.add_mutually_exclusive_group()
    g.add_argument("--aoa-mrad", type=float, help="angle of attack [mrad] (default 10)")
    g.add_argument("--crabbing", type=float, help="crabbing velocity Vc [m/s]")
    g.add_argument("--sweep", type=float, nargs=3, metavar=("VC_START", "VC_STOP", "N"),
                   help="sweep the crabbing velocity [m/s]")
    q.add_argument("--k3-convention", choices=K3_CONVENTIONS)
    for dest, (flag, unit) in _SQUEAL_OVERRIDES.items():
        q.add_argument(flag, dest=dest, type=float, help=f"override [{unit}]")
    q.add_argument("--reference", type=float, help="A w_ref of the relative level [m/s] (default: the largest A w)")
    q.add_argument("--ode", action="store_true", help="also integrate the ODE for every row (about 1 s each)")
    q.add_argument("--json", action="store_true", help="print JSON instead of a table")
    q.add_argument("--plot", help="save amplitude and relative level against Vc to this PNG")
    q.set_defaults(func=cmd_predict_squeal)

    c = models.add_parser("corrugation", help="corrugation growth per wavelength band, time to the grinding "
                          "threshold, and speed advice", formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    _site_option(c)
    g = c.add_mutually_exclusive_group()
    g.add_argument("--history", help="pass history (bag folder, .mcap, .db3 or .csv): state, speeds and traffic "
                   "from it")
    g.add_argument("--speeds", type=float, nargs="+", help="speed histogram bin centres [m/s]")
    c.add_argument("--weights", type=float, nargs="+", help="weights of --speeds (default: equal)")
    c.add_argument("--vehicle-class", help="vehicle class without --history (default: the site's first)")
    c.add_argument("--speed-mean", type=float, help="mean speed of a normal distribution [m/s] (default: the class's)")
    c.add_argument("--speed-cv", type=float, help="its coefficient of variation [-] (default: the class's sd/mean)")
    c.add_argument("--friction", choices=tuple(FRICTION_BY_NAME),
                   help="friction state (default: dry, or the history's mix)")
    c.add_argument("--passes-per-day", type=float, help="train passes per day (default: the history's)")
    c.add_argument("--advise", action="store_true", help="also propose a speed distribution with the same mean")
    c.add_argument("--json", action="store_true", help="print JSON instead of a table")
    c.add_argument("--plot-receptance", metavar="PNG", help="save the track and wheel receptances to this PNG")
    c.add_argument("--plot-growth", metavar="PNG", help="save growth against wavelength (current and advised)")
    c.set_defaults(func=cmd_predict_corrugation)

    r = models.add_parser("noise", help="rolling noise pass-by levels and spectra (CNOSSOS-EU and mechanics), "
                          "before and after roughness growth", formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    _site_option(r)
    r.add_argument("--vehicle-class", help="vehicle class (default: the site's first)")
    r.add_argument("--speed", type=float, nargs="+", help="train speeds [m/s] (default: the class's mean)")
    r.add_argument("--vehicles", type=int, help="vehicles in the train (default: the class's mean consist)")
    r.add_argument("--model", dest="noise_model", choices=("cnossos", "mechanics", "both"),
                   help="source model (default: the site's noise.model)")
    r.add_argument("--rail-roughness", choices=("E", "M"), help="baseline rail roughness class")
    r.add_argument("--sleeper-type", choices=("monoblock", "biblock", "wooden", "direct_fastening"))
    r.add_argument("--pad-stiffness", type=float, help="rail pad stiffness [N/m] (track.pad_stiffness_npm)")
    r.add_argument("--interpolation", choices=("reference", "energy_log_frequency"))
    r.add_argument("--distance", type=float, help="receiver distance from the track centre [m]")
    r.add_argument("--growth-days", type=float, nargs="+",
                   help="also predict after this many days of corrugation growth from grinding (at the first speed)")
    r.add_argument("--passes-per-day", type=float, default=100.0, help="trains per day for --growth-days")
    r.add_argument("--json", action="store_true", help="print JSON (spectra and single numbers) instead of a table")
    r.add_argument("--plot", metavar="PNG", help="save A-weighted spectra at the speeds and after growth")
    r.set_defaults(func=cmd_predict_noise)

    s = sub.add_parser("batch", help="the graph's models over a whole history without DDS (vectorised), "
                       "recorded to a bag like the live graph, with the report")
    s.add_argument("source", help="bag folder, .mcap, .db3 or .csv")
    _site_option(s)
    s.add_argument("--topic", help="TrainPass topic of the bag (default: the only one)")
    s.add_argument("--output", help="bag folder to write (default: <source>_batch)")
    s.add_argument("--namespace", help="topic namespace in the bag (default: the site_id)")
    s.add_argument("--report", help="report folder (default: <output>_report)")
    s.add_argument("--no-report", action="store_true", help="write the bag only")
    s.add_argument("--overwrite", action="store_true", help="replace an existing output folder")
    s.add_argument("--salvage", action="store_true", help=_SALVAGE_HELP)
    s.set_defaults(func=cmd_batch)

    s = sub.add_parser("report", help="print the summary of a recorded run and write its report folder "
                       "(PNG plots, index.html)")
    s.add_argument("bag", help="bag recorded by the graph or by batch")
    _site_option(s)
    s.add_argument("--out", help="report folder (default: <bag>_report)")
    s.set_defaults(func=cmd_report)

    for name, helptext in (("monitor", "run the whole graph in one process on a history"),
                           ("demo", "the main job: the bundled sample history through the whole graph")):
        s = sub.add_parser(name, help=helptext)
        if name == "monitor":
            s.add_argument("source", help="bag folder, .mcap, .db3 or .csv")
            s.add_argument("--output", help="bag folder to record into")
        else:
            s.add_argument("--source", type=Path, default=DEFAULT_SAMPLE, help="history to replay")
            s.add_argument("--output", default="out/demo", help="bag folder to record into")
        _site_option(s)
        s.add_argument("--namespace", help="site namespace (default: the site_id)")
        s.add_argument("--report", help="report folder (default: <output>_report)")
        s.add_argument("--no-report", action="store_true", help="record only: no summary or report")
        s.add_argument("--overwrite", action="store_true", default=name == "demo",
                       help="replace an existing output folder")
        _add_specs(s, MONITOR_SPECS + PUBLISH_SPECS, skip=("site_id", "wait_for_subscribers", "wait_timeout_s"))
        s.set_defaults(func=cmd_demo if name == "demo" else cmd_monitor)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    # Anything from --ros-args on goes to the nodes untouched (e.g. -p executor:=events).
    cut = argv.index("--ros-args") if "--ros-args" in argv else len(argv)
    ns = build_parser().parse_args(argv[:cut])
    ns.ros_extra = argv[cut:]
    try:
        return ns.func(ns)
    except RailMonitorError as exc:
        print(f"rail-monitor: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
