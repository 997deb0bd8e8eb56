"""rail-monitor predict roughness as a user runs it (rail_monitor.cli.predict_roughness)."""

from __future__ import annotations

import json

import numpy as np


def test_indirect_roughness_from_a_bag_s_measurements_is_labelled_and_equals_the_library(tmp_path, site_values,
                                                                                          sample_passes, capsys):
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.batch.run import run_models
    from rail_monitor.cli import main
    from rail_monitor.simulation.measurements import simulate_measurements
    from rail_monitor.whatif.roughness import indirect_of_run

    passes = sample_passes.sorted().take(slice(0, 1500))
    first = run_models(passes, site_values)
    p = first.noise["cnossos"]
    ms = simulate_measurements(first.accepted, p.lp_db, p.lpaeq_tp_dba, p.lpafmax_dba, p.tel_dba, p.band_centre_hz,
                               (7.5, 1.2), seed=2).measurements
    bag = write_passes_bag(passes, tmp_path / "h", "curve_250", measurements=ms)
    assert main(["predict", "roughness", "--history", str(bag), "--days", "10", "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert "CEN/TR 16891" in got["what"] and "not an EN 15610 measurement" in got["what"]
    want = indirect_of_run(run_models(passes, site_values, measurements=ms), site_values, 10.0)
    level = np.array([np.nan if b["indirect_db"] is None else b["indirect_db"] for b in got["bands"]])
    np.testing.assert_allclose(level, want.level_db, rtol=1e-12, equal_nan=True)
    assert np.isfinite(level).sum() >= 10
    assert main(["predict", "roughness", "--history", str(bag)]) == 0
    assert capsys.readouterr().out.startswith("# indirect rail roughness")
