"""A noise station's CSV (rail_monitor.bagio.measured_csv): the documented layout round-trips, a
row that does not parse names its line, and rail-monitor batch --measured pairs it as a bag's."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.bagio.measured_csv import read_measured_csv, write_measured_csv
from rail_monitor.core.errors import InputError
from rail_monitor.measured.records import Measurement
from rail_monitor.noise.config import band_centres_hz

BANDS = band_centres_hz()


def _measurements(n: int = 3) -> list[Measurement]:
    rng = np.random.default_rng(2)
    return [Measurement(1_790_000_000 * 10**9 + i * 123_456_789, f"T,{i}", 7.5, 1.2, 1 + i % 2, BANDS.copy(),
                        rng.uniform(50, 90, len(BANDS)), 80.0 + i / 3, 83.1, 85.2, i == 1,
                        ("V=1", "V2") if i else (), np.array([80.5, 79.25]) if i else np.zeros(0))
            for i in range(n)]


def test_the_layout_round_trips_losslessly(tmp_path):
    ms = _measurements()
    write_measured_csv(ms, tmp_path / "m.csv")
    back = read_measured_csv(tmp_path / "m.csv")
    assert len(back) == 3 and not back.skipped_rows
    for a, b in zip(ms, back, strict=True):
        assert (a.stamp_ns, a.train_id, a.instrument_class, a.squeal_detected, a.vehicle_id) == \
            (b.stamp_ns, b.train_id, b.instrument_class, b.squeal_detected, b.vehicle_id)
        np.testing.assert_array_equal(a.leq_db, b.leq_db)
        np.testing.assert_array_equal(a.band_centre_hz, b.band_centre_hz)
        np.testing.assert_array_equal(a.vehicle_lpaeq_dba, b.vehicle_lpaeq_dba)
        assert (a.lpaeq_tp_dba, a.lpafmax_dba, a.tel_dba) == (b.lpaeq_tp_dba, b.lpafmax_dba, b.tel_dba)


def test_a_bad_row_names_its_line_or_is_skipped_and_counted(tmp_path):
    write_measured_csv(_measurements(), tmp_path / "m.csv")
    lines = (tmp_path / "m.csv").read_text().splitlines()
    lines[4] = lines[4].replace("7.5,1.2,2,", "7.5,1.2,two,")  # the second pass (line 5): class 2
    (tmp_path / "bad.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"bad.csv: line 5: column 'instrument_class'"):
        read_measured_csv(tmp_path / "bad.csv")
    kept = read_measured_csv(tmp_path / "bad.csv", skip_bad_rows=True)
    assert len(kept) == 2 and kept.skipped_rows[0].startswith("line 5:")
    (tmp_path / "cols.csv").write_text("time_utc,train_id\n2026-09-01T00:00:00Z,T1\n")
    with pytest.raises(InputError, match=r"missing column.*receiver_distance_m.*leq_<centre>hz_db"):
        read_measured_csv(tmp_path / "cols.csv")


def test_batch_pairs_a_station_csv_as_it_pairs_a_bag_s_measurements(tmp_path, site_values, sample_passes, capsys):
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.bagio.reader import read_messages
    from rail_monitor.batch.run import run_models
    from rail_monitor.cli import main
    from rail_monitor.simulation.measurements import simulate_measurements

    passes = sample_passes.sorted().take(slice(0, 600))
    first = run_models(passes, site_values)
    p = first.noise["cnossos"]
    ms = simulate_measurements(first.accepted, p.lp_db, p.lpaeq_tp_dba, p.lpafmax_dba, p.tel_dba, p.band_centre_hz,
                               (7.5, 1.2), seed=1).measurements
    write_measured_csv(ms, tmp_path / "station.csv")
    plain = write_passes_bag(passes, tmp_path / "plain", "curve_250")
    both = write_passes_bag(passes, tmp_path / "both", "curve_250", measurements=ms)
    assert main(["batch", str(plain), "--measured", str(tmp_path / "station.csv"), "--output",
                 str(tmp_path / "a"), "--no-report"]) == 0
    assert f"{len(ms)} measured pass-by(s) paired with their predictions, 0 refused" in capsys.readouterr().out
    assert main(["batch", str(both), "--output", str(tmp_path / "b"), "--no-report"]) == 0
    ra, rb = (read_messages(tmp_path / x, ["rail_msgs/msg/NoiseResidual"])["rail_msgs/msg/NoiseResidual"]
              for x in "ab")
    assert len(ra) == len(rb) == 2 * len(ms)
    assert [r.excess_mid_db for r in ra] == pytest.approx([r.excess_mid_db for r in rb], nan_ok=True, rel=0, abs=0)
    # the export has the measured levels and each model's residuals, row by row on their passes
    assert main(["export", str(tmp_path / "a"), "--format", "csv"]) == 0
    import csv

    rows = list(csv.DictReader(line for line in (tmp_path / "a_export" / "passes.csv").read_text().splitlines()
                               if not line.startswith("#")))
    by_id = {r["train_id"]: r for r in rows}
    m = ms[5]
    got = by_id[m.train_id]
    assert float(got["measured_lpaeq_tp_dba"]) == pytest.approx(m.lpaeq_tp_dba, abs=1e-9)
    want = next(r for r in ra if r.train_id == m.train_id and r.model == "cnossos")
    assert float(got["cnossos_residual_mid_db"]) == pytest.approx(want.residual_mid_db, abs=1e-9)
