"""Batch mode over many sites on a Dask cluster (issue 22): a manifest of two sites, run as one
task per site on a local cluster of 2 workers, gives each site what a batch run of that site
alone gives: the same passes, alerts and stored site exactly, and every number to 1e-12 relative
(measured: 3.6e-15, float rounding that varies with where an array sits in memory, as numpy's
vectorised sums do, between one process and another); a bad manifest is one line."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.bagio.site_record import read_site_record
from rail_monitor.batch.sites import read_manifest
from rail_monitor.cli import main
from rail_monitor.core.errors import ConfigError
from rail_monitor.report.run_data import load_run

from conftest import write_two_sites


@pytest.fixture(scope="module")
def two_sites(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sites")
    write_two_sites(tmp, 1.0)
    (tmp / "sites.yaml").write_text("sites:\n  - site: curve_250.yaml\n    history: a.csv\n"
                                    "  - site: curve_400.yaml\n    history: b.csv\n    output: out/b\n")
    return tmp


def test_each_site_of_a_two_worker_cluster_equals_its_own_batch_run(two_sites, capsys):
    tmp = two_sites
    assert main(["batch", "--manifest", str(tmp / "sites.yaml"), "--workers", "2"]) == 0
    printed = capsys.readouterr().out
    assert "2 sites" in printed and "site curve_250" in printed and "site curve_400" in printed
    cases = (("curve_250.yaml", "a.csv", tmp / "a_batch"), ("curve_400.yaml", "b.csv", tmp / "out" / "b"))
    for site, history, bag in cases:
        alone = tmp / f"alone_{site}"
        assert main(["batch", str(tmp / history), "--site", str(tmp / site), "--output", str(alone),
                     "--no-report"]) == 0
        run, want = load_run(bag), load_run(alone)
        assert read_site_record(bag) == read_site_record(alone)
        assert run.passes.equals(want.passes)
        for k in ("amplitude_m", "days_to_threshold"):
            np.testing.assert_allclose(run.states[k], want.states[k], rtol=1e-12, atol=0)
        assert np.abs(run.states["grinding_due_time"] - want.states["grinding_due_time"]).max() <= 10**6  # 1 ms
        for model, nz in want.noise.items():
            np.testing.assert_allclose(run.noise[model]["lpaeq_tp_dba"], nz["lpaeq_tp_dba"], rtol=1e-12, atol=0)
        np.testing.assert_array_equal(run.squeal["level_dba"], want.squeal["level_dba"])
        assert run.alerts == want.alerts


def test_a_bad_manifest_is_one_line(tmp_path):
    m = tmp_path / "m.yaml"
    for text, why in (("sites: []\n", "expected 'sites:'"), ("sites:\n  - site: x.yaml\n", "expected the keys"),
                      ("sites:\n  - site: x.yaml\n    history: y.csv\n", "not found")):
        m.write_text(text)
        with pytest.raises(ConfigError, match=why):
            read_manifest(m)
