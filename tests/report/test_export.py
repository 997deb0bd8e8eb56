"""rail-monitor export (issue 24): every format opens with pandas/pyarrow and holds exactly the
values recorded in the bag, joined to the right pass."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from rail_monitor.cli import main
from rail_monitor.report.run_data import load_run

from conftest import EXAMPLE_CSV


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("export")
    csv = tmp / "detector.csv"
    csv.write_text(EXAMPLE_CSV.read_text())
    assert main(["batch", str(csv), "--no-report"]) == 0
    bag = tmp / "detector_batch"
    for fmt in ("csv", "parquet", "xlsx"):
        assert main(["export", str(bag), "--format", fmt, "--output", str(tmp / fmt)]) == 0
    read = {
        "csv": lambda name: pd.read_csv(tmp / "csv" / f"{name}.csv", float_precision="round_trip"),
        "parquet": lambda name: pd.read_parquet(tmp / "parquet" / f"{name}.parquet"),
        "xlsx": lambda name: pd.read_excel(tmp / "xlsx" / "run.xlsx", sheet_name=name),
    }
    return load_run(bag), {fmt: {t: f(t) for t in ("passes", "alerts")} for fmt, f in read.items()}, tmp


@pytest.mark.parametrize("fmt", ["csv", "parquet", "xlsx"])
def test_every_format_round_trips_the_bag_values(exported, fmt):
    """CSV and Parquet exactly; Excel to 1e-15 relative (openpyxl writes 16 significant digits, and
    Excel itself keeps 15: ECMA-376 numbers are doubles shown to 15 digits)."""
    run, tables, _ = exported
    rtol = 1e-15 if fmt == "xlsx" else 0.0

    def same(a, b) -> bool:
        return bool(np.isclose(a, b, rtol=rtol, atol=0.0))

    passes, alerts = tables[fmt]["passes"], tables[fmt]["alerts"]
    assert len(passes) == len(run.passes) and list(passes["train_id"]) == run.passes.train_id.tolist()
    assert [int(t) for t in passes["stamp_ns"]] == run.passes.stamp_ns.tolist()  # Excel: as text, unrounded
    np.testing.assert_array_equal(passes["speed_mps"].to_numpy(), run.passes.speed_mps)  # exact
    for model, nz in run.noise.items():  # joined by (train_id, stamp): the recorded value of that pass
        keys = zip(passes["train_id"], map(int, passes["stamp_ns"]), strict=True)
        got = dict(zip(keys, passes[f"{model}_lpaeq_tp_dba"], strict=True))
        want = dict(zip(zip(nz["train_id"], nz["stamp_ns"].tolist(), strict=True), nz["lpaeq_tp_dba"], strict=True))
        assert all(same(got[k], v) for k, v in want.items()), model
    level = run.squeal["level_dba"]
    assert np.isnan(passes["squeal_level_dba"].to_numpy()).sum() == (~np.isfinite(level)).sum()  # no squeal: empty
    assert set(passes["squeal_risk"]) <= {"none", "low", "medium", "high"}
    last = passes["corrugation_worst_rms_um"].to_numpy()[-1]
    w = int(run.states["worst_band"][-1])
    assert same(last, 1e6 * run.states["amplitude_m"][-1, w])  # the state after the last pass
    assert len(alerts) == len(run.alerts) and list(alerts["event"]) == ["raised" if a.active else "cleared"
                                                                       for a in run.alerts]


def test_parquet_carries_units_and_the_site(exported):
    _, _, tmp = exported
    schema = pq.read_schema(tmp / "parquet" / "passes.parquet")
    assert schema.field("speed_kmh").metadata[b"unit"] == b"km/h"
    assert schema.field("cnossos_lpaeq_tp_dba").metadata[b"unit"] == b"dB(A)"
    assert schema.field("stamp_ns").type == "int64"
    assert b"site.site_file" in schema.metadata and b"rail_monitor.version" in schema.metadata
    units = pd.read_excel(tmp / "xlsx" / "run.xlsx", sheet_name="columns")
    assert set(units["column"]) >= {"speed_kmh", "squeal_level_dba"}


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_an_export_in_parts_equals_the_whole_one(exported, fmt):
    # Streamed (a few passes at a time, the state before each part carried) against read whole.
    _, _, tmp = exported
    bag = tmp / "detector_batch"
    for chunk in ("7", "0"):
        out = str(tmp / f"{fmt}{chunk}")
        assert main(["export", str(bag), "--format", fmt, "--chunk", chunk, "--output", out]) == 0
    for name in ("passes", "alerts"):
        parts, whole = (tmp / f"{fmt}{c}" / f"{name}.{fmt}" for c in ("7", "0"))
        if fmt == "csv":
            assert parts.read_bytes() == whole.read_bytes()
        else:
            a, b = pq.read_table(parts), pq.read_table(whole)
            assert a.schema.equals(b.schema, check_metadata=True) and a.equals(b)
            assert pq.ParquetFile(parts).num_row_groups > 1 or name == "alerts"


def test_a_bag_not_logged_at_its_stamps_is_exported_whole(tmp_path, capsys):
    from rail_monitor.bagio.mcap_bag import McapBagWriter
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.codec.cdr import serialize
    from rail_monitor.messages.fields import train_pass_fields
    from rail_monitor.messages.topics import GRAPH_TOPICS

    passes = read_passes(EXAMPLE_CSV)
    typename, qos = GRAPH_TOPICS["train_pass"]
    with McapBagWriter(tmp_path / "received") as bag:  # as a recorder logging receive times would
        bag.add_topic("/site/train_pass", typename, [qos.as_metadata()])
        for i in range(len(passes)):
            bag.write("/site/train_pass", serialize(typename, train_pass_fields(passes.row(i), "curve_250")),
                      int(passes.stamp_ns[i]) + 1_000)
    assert main(["export", str(tmp_path / "received"), "--chunk", "5", "--output", str(tmp_path / "out")]) == 0
    assert "not at its stamp" in capsys.readouterr().out
    assert len(pd.read_csv(tmp_path / "out" / "passes.csv")) == len(passes)
