"""Rolling-noise benchmark: per-site set-up, per-pass prediction cost of each model, batch throughput.

Run: ros2_ws/run python -m bench.noise [--passes N]
Prints figures measured in this run only (compare ratios, not absolute times, across machines).
"""

from __future__ import annotations

import time

from bench.corrugation import passes
from bench.timing import best_of, header, parser
from rail_monitor.core.site import site_from_values
from rail_monitor.models.corrugation_bands import band_limits, wavelength_bands
from rail_monitor.noise.config import MODELS, PASS_BY_SOURCES, noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import Corrugation
from rail_monitor.site_file import load_parameter_file


def costs(site_file: str, n: int = 20_000) -> dict[str, dict[str, float]]:
    """Per-pass cost [s] of each source model with a corrugation state: one pass alone (a node's
    call on a live pass) and in a batch of n (the node on a backlog, batch mode)."""
    values = load_parameter_file(site_file)
    model = RollingNoiseModel(site_from_values(values), noise_config(values))
    bands = wavelength_bands(0.01, 1.0)
    post = 0.5 * band_limits(bands)
    state = Corrugation(bands, 3 * post, post)
    one, table = passes(model.site, 1), passes(model.site, n)
    return {name: {"pass_single": best_of(lambda name=name: model.predict(one, name, state), 30),
                   "pass_batch": best_of(lambda name=name: model.predict(table, name, state), 2) / n}
            for name in MODELS}


def main() -> None:
    ap = parser(__doc__)
    ap.add_argument("--passes", type=int, default=100_000, help="passes of the batch run")
    ns = ap.parse_args()
    values = load_parameter_file(ns.site)
    site, cfg = site_from_values(values), noise_config(values)
    header("rolling-noise")
    t = time.perf_counter()
    model = RollingNoiseModel(site, cfg)
    print(f"site set-up (tables, per-class transfers of both models): {1e3 * (time.perf_counter() - t):8.2f} ms")
    bands = wavelength_bands(0.01, 1.0)
    post = 0.5 * band_limits(bands)
    state = Corrugation(bands, 3 * post, post)
    one = passes(site, 1)
    for name in MODELS:
        bare = best_of(lambda name=name: model.predict(one, name), 50)
        grown = best_of(lambda name=name: model.predict(one, name, state), 50)
        print(f"{name:>9}: per pass {1e3 * bare:6.2f} ms; with a corrugation state (two roughness cases) "
              f"{1e3 * grown:6.2f} ms")
    table = passes(site, ns.passes)
    # The pass-by sources in one run: the moving point sources per axle against the line source.
    for sources in PASS_BY_SOURCES:
        by = RollingNoiseModel(site, noise_config({**values, "noise.pass_by_sources": sources}))
        for name in MODELS:
            t = best_of(lambda name=name, by=by: by.predict(table, name, state), 1)
            print(f"{name:>9}, {sources:>5} sources: batch of {ns.passes} passes with a corrugation state "
                  f"{t:6.2f} s = {ns.passes / t:9.0f} passes/s")


if __name__ == "__main__":
    main()
