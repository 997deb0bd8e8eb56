"""rail-monitor predict passby-audio: a predicted pass written as the receiver would record it (WAV)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rail_monitor.cli.common import add_site_option, print_json, site_values
from rail_monitor.core.errors import RailMonitorError


def add_parser(models: argparse._SubParsersAction) -> None:
    from rail_monitor.core.passes import FRICTION_BY_NAME
    from rail_monitor.noise.config import MODELS

    a = models.add_parser("passby-audio", help="the WAV of a predicted pass at the receiver (rolling noise and "
                          "squeal), in pascals")
    add_site_option(a)
    a.add_argument("--output", required=True, help="the WAV file to write (32-bit float, in pascals: read it back "
                   "with rail-monitor measure passby --sensitivity 1)")
    a.add_argument("--vehicle-class", help="vehicle class (default: the site's first)")
    a.add_argument("--speed", type=float, help="train speed [m/s] (default: the class's mean)")
    a.add_argument("--vehicles", type=int, help="vehicles in the train (default: the class's mean consist)")
    a.add_argument("--friction", default="dry", choices=tuple(FRICTION_BY_NAME), help="friction state")
    a.add_argument("--aoa-mrad", type=float, default=0.0, help="angle of attack [mrad] (squeal needs one)")
    a.add_argument("--model", dest="noise_model", choices=MODELS, help="rolling noise model (default: the site's)")
    a.add_argument("--no-squeal", action="store_true", help="rolling noise only")
    a.add_argument("--seed", type=int, default=0, help="seed of the noise")
    a.add_argument("--json", action="store_true", help="print JSON instead of a summary")
    a.set_defaults(func=run)


def run(ns: argparse.Namespace) -> int:
    import numpy as np
    from scipy.io import wavfile

    from rail_monitor.whatif.audio import pass_audio

    out = Path(ns.output)
    if out.exists() or out.is_symlink():
        raise RailMonitorError(f"{out} exists: give a new file name (a recording is never replaced)")
    a = pass_audio(site_values(ns.site), ns.vehicle_class, ns.speed, ns.vehicles, ns.friction, ns.aoa_mrad,
                   ns.noise_model, not ns.no_squeal, seed=ns.seed)
    tmp = out.with_name(f".{out.name}.tmp")
    try:
        wavfile.write(tmp, int(a.fs_hz), a.pressure_pa.astype(np.float32))
        tmp.replace(out)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise RailMonitorError(f"{out}: cannot write: {exc.strerror or exc}") from None
    facts = {"wav": str(out), "fs_hz": a.fs_hz, "pass_start_s": a.pass_start_s, "pass_time_s": a.pass_time_s,
             "model": a.model, "lpaeq_tp_dba": a.lpaeq_tp_dba, "lpafmax_dba": a.lpafmax_dba, "tel_dba": a.tel_dba,
             "band_centre_hz": a.band_centre_hz.tolist(), "lp_db": a.lp_db.tolist(),
             "squeal_hz": a.squeal_hz, "squeal_db": a.squeal_db}
    if ns.json:
        print_json(facts)
        return 0
    print(f"wrote {out}: {len(a.pressure_pa) / a.fs_hz:.1f} s at {a.fs_hz:g} Hz, the pass from {a.pass_start_s:.1f} s "
          f"for {a.pass_time_s:.2f} s; predicted ({a.model}, line source) LpAeq,Tp {a.lpaeq_tp_dba:.1f} dB(A), "
          f"LpAFmax {a.lpafmax_dba:.1f} dB(A), TEL {a.tel_dba:.1f} dB(A); "
          + (f"squeal at {a.squeal_hz:.0f} Hz, {a.squeal_db:.1f} dB" if a.squeal_hz == a.squeal_hz else "no squeal"))
    return 0
