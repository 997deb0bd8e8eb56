"""rail-monitor measure: what a station records, reduced as the standards say (a pass-by's audio)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rail_monitor.cli.common import add_site_option, print_json
from rail_monitor.core.errors import RailMonitorError


def add_parser(sub: argparse._SubParsersAction) -> None:
    m = sub.add_parser("measure", help="reduce a station's recording (a pass-by's audio)")
    what = m.add_subparsers(dest="what", required=True)
    p = what.add_parser("passby", help="ISO 3095 levels, 1/3-octave bands, tones and squeal of a recorded pass-by")
    p.add_argument("wav", help="the pass-by's recording (WAV, one channel used, at least 25.6 kHz)")
    p.add_argument("--calibration-file", help="a recording of a calibrator on the same channel (WAV)")
    p.add_argument("--calibration-db", type=float, default=94.0,
                   help="the calibrator's level [dB re 20 uPa]")
    p.add_argument("--sensitivity", type=float,
                   help="pascals per full-scale unit of the recording, instead of a calibration file")
    p.add_argument("--channel", type=int, default=0, help="the channel of a multi-channel file (0 first)")
    p.add_argument("--start-s", type=float, help="the train's front at the microphone [s from the start] "
                   "(default: the record's start)")
    p.add_argument("--end-s", type=float, help="the train's rear at the microphone [s] (default: the record's end)")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=run_passby)
    r = what.add_parser("roughness", help="rail roughness per 1/3-octave wavelength band from a trolley's trace")
    r.add_argument("trace", help="CSV: distance_m and displacement_um (or displacement_m), evenly spaced")
    r.add_argument("--wheel-radius-m", type=float, default=0.46, help="radius of the wheel of the curvature "
                   "processing [m]")
    r.add_argument("--json", action="store_true", help="print JSON instead of a table")
    r.add_argument("--survey-bag", help="also write the spectrum as a roughness survey (a bag folder of one "
                   "rail_msgs/RoughnessSurvey) that batch --surveys and the graph take; needs --stamp")
    r.add_argument("--stamp", help="when the trace was measured (ISO 8601 UTC, e.g. 2026-09-01T06:00:00Z)")
    add_site_option(r)
    r.set_defaults(func=run_roughness)


def run_passby(ns: argparse.Namespace) -> int:
    from rail_monitor.station.pass_audio import hear, sensitivity

    if (ns.calibration_file is None) == (ns.sensitivity is None):
        raise RailMonitorError("give one of --calibration-file (with --calibration-db) or --sensitivity")
    if ns.sensitivity is not None and not 0.0 < ns.sensitivity < float("inf"):
        raise RailMonitorError(f"--sensitivity must be a positive number of pascals, not {ns.sensitivity:g}")
    scale = sensitivity(ns.sensitivity or 0.0, ns.calibration_file, ns.calibration_db, ns.channel)
    heard = hear(ns.wav, scale, ns.channel, ns.start_s, ns.end_s)
    r, d = heard.levels, heard.squeal
    tones = [{"frequency_hz": t.frequency_hz, "level_db": t.level_db, "audibility_db": t.audibility_db}
             for t in r.tones]
    squeal = {"detected": d.squeal, "frequency_hz": d.frequency_hz, "level_db": d.level_db,
              "duration_s": d.duration_s, "share": d.share, "flanging": d.flanging, "flanging_s": d.flanging_s}
    if ns.json:
        print_json({"lpaeq_tp_db": r.lpaeq_tp_db, "lpafmax_db": r.lpafmax_db, "tel_db": r.tel_db, "sel_db": r.sel_db,
                    "tp_s": r.tp_s, "record_s": r.record_s, "sensitivity_pa_per_unit": scale,
                    "band_centres_hz": r.band_centres_hz.tolist(), "band_levels_db": r.band_levels_db.tolist(),
                    "tones": tones, "squeal": squeal})
        return 0
    print(f"# {ns.wav}: pass {r.tp_s:.2f} s of a {r.record_s:.2f} s record; dB re 20 uPa")
    print(f"LpAeq,Tp {r.lpaeq_tp_db:6.1f} dB(A)   LpAFmax {r.lpafmax_db:6.1f} dB(A)   TEL {r.tel_db:6.1f} dB(A)   "
          f"SEL {r.sel_db:6.1f} dB(A)")
    print("band [Hz]  " + " ".join(f"{c:>6g}" for c in r.band_centres_hz))
    print("Leq,Tp     " + " ".join(f"{v:6.1f}" for v in r.band_levels_db))
    for t in tones:
        print(f"tone {t['frequency_hz']:8.1f} Hz  {t['level_db']:6.1f} dB  audibility {t['audibility_db']:+5.1f} dB")
    if not tones:
        print("no audible tone")
    print(f"squeal at {d.frequency_hz:.0f} Hz, {d.level_db:.1f} dB, for {d.duration_s:.1f} s ({100 * d.share:.0f} % of "
          "the pass)" if d.squeal else "no squeal", f"; flanging for {d.flanging_s:.1f} s" if d.flanging else "")
    return 0


def run_roughness(ns: argparse.Namespace) -> int:
    from rail_monitor.bagio.trace_csv import read_trace
    from rail_monitor.models.rail_roughness import roughness_spectrum

    if bool(ns.survey_bag) != bool(ns.stamp):
        raise RailMonitorError("--survey-bag and --stamp go together: a survey is of a time")
    dx, z = read_trace(ns.trace)
    if not 0.0 < ns.wheel_radius_m < 5.0:
        raise RailMonitorError(f"--wheel-radius-m must be between 0 and 5 m, not {ns.wheel_radius_m:g}")
    try:
        s = roughness_spectrum(z, dx, ns.wheel_radius_m)
    except ValueError as exc:
        raise RailMonitorError(f"{ns.trace}: {exc}") from None
    if ns.survey_bag:
        _survey_bag(ns, s)
    if ns.json:
        print_json({"length_m": s.length_m, "spacing_m": dx, "spikes_removed": s.spikes,
                    "wavelength_m": s.wavelength_m.tolist(), "rms_m": s.rms_m.tolist(),
                    "level_db": s.level_db.tolist()})
        return 0
    print(f"# {ns.trace}: {s.length_m:.2f} m at {1e3 * dx:g} mm, {s.spikes} sample(s) replaced as spikes; "
          "dB re 1 um")
    print(f"{'lambda [mm]':>11} {'level':>7} {'r.m.s. [um]':>11}")
    for lam, lv, rms in zip(s.wavelength_m, s.level_db, s.rms_m, strict=True):
        print(f"{1e3 * lam:11.1f} {lv:7.1f} {1e6 * rms:11.3f}")
    return 0


def _survey_bag(ns: argparse.Namespace, s) -> None:
    """The spectrum's resolved bands (r.m.s. above 0) as a survey at --stamp, in a new bag folder."""
    import numpy as np

    from rail_monitor.bagio.passes_bag import write_survey_bag
    from rail_monitor.cli.common import fresh_output, site_values
    from rail_monitor.core.timeutil import parse_iso_ns
    from rail_monitor.corrugation.surveys import KIND_SURVEY, MaintenanceEvent

    try:
        stamp = parse_iso_ns(ns.stamp)
    except RailMonitorError as exc:
        raise RailMonitorError(f"--stamp: {exc}") from None
    keep = np.isfinite(s.rms_m) & (s.rms_m > 0.0)
    if not keep.any():
        raise RailMonitorError(f"{ns.trace}: no band of the trace has roughness to survey")
    fresh_output(Path(ns.survey_bag), False, [ns.trace])
    site_id = str(site_values(ns.site).get("site_id", ""))
    write_survey_bag([MaintenanceEvent(stamp, KIND_SURVEY, s.wavelength_m[keep], s.rms_m[keep])], ns.survey_bag,
                     site_id, f"/{site_id}/roughness_survey" if site_id else "/roughness_survey")
    if not ns.json:
        print(f"# survey of {keep.sum()} band(s) at {ns.stamp} written to {ns.survey_bag}")
