"""Detector CSV: lossless round trip, units by column name, clear errors naming line or column."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rail_monitor.bagio.csv_io import read_csv, read_csv_rows, write_csv
from rail_monitor.core.errors import InputError

from conftest import EXAMPLE_CSV


def test_round_trip_is_lossless(tmp_path: Path, sample_passes):
    part = sample_passes.take(slice(0, 500))
    write_csv(part, tmp_path / "p.csv")
    assert read_csv(tmp_path / "p.csv").equals(part)


def test_bundled_example_reads(site):
    t = read_csv(EXAMPLE_CSV)
    assert len(t) > 100 and set(t.vehicle_class) <= set(site.vehicles)


def test_other_units_convert(tmp_path: Path):
    p = tmp_path / "u.csv"
    p.write_text("time_unix_s,train_id,vehicle_class,axle_count,speed_kmh,angle_of_attack_mrad,wheel_load_kn,"
                 "friction_state,detector_note\n1790000000.5,T1,emu,12,72,5,65,WET,ok\n", encoding="utf-8")
    t = read_csv(p)
    assert t.stamp_ns[0] == 1_790_000_000_500_000_000
    assert np.isclose(t.speed_mps[0], 20.0) and np.isclose(t.angle_of_attack_rad[0], 0.005)
    assert np.isclose(t.wheel_load_n[0], 65000.0) and t.friction_state[0] == 2
    assert t.vehicle_count[0] == 0 and t.train_length_m[0] == 0.0  # optional columns default to 0


HEADER = "time_utc,train_id,vehicle_class,vehicle_count,speed_mps,angle_of_attack_rad,friction_state\n"
ROW = "2026-09-01T05:00:00Z,T1,emu,3,19.0,0.005,dry\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (HEADER.replace(",speed_mps", ""), "missing column(s): speed_mps or speed_kmh"),
        (HEADER.replace("speed_mps", "speed_mph"), "column 'speed_mph' has a unit"),
        (HEADER + ROW + ROW.replace("19.0", "fast"), "line 3: column 'speed_mps'"),
        (HEADER + ROW.replace(",dry", ""), "line 2: 6 fields where the header has 7"),
        (HEADER + ROW.replace("dry", "icy"), "line 2: column 'friction_state': unknown friction state 'icy'"),
        (HEADER + ROW.replace("2026-09-01T05:00:00Z", "yesterday"), "line 2: column 'time_utc'"),
        ("", "no header line"),
    ],
)
def test_bad_files_name_the_line_or_column(tmp_path: Path, text: str, message: str):
    p = tmp_path / "bad.csv"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as err:
        read_csv(p)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_not_utf8_names_the_line(tmp_path: Path):
    p = tmp_path / "latin1.csv"
    p.write_bytes((HEADER + ROW.replace("T1", "Zug\xe41")).encode("latin-1"))
    with pytest.raises(InputError, match="line 2: not UTF-8"):
        read_csv(p)


def test_skip_bad_rows_counts_them(tmp_path: Path):
    p = tmp_path / "some_bad.csv"
    p.write_text(HEADER + ROW + ROW.replace("19.0", "x") + ROW.replace("T1", "T2"), encoding="utf-8")
    t, skipped = read_csv_rows(p, skip_bad_rows=True)
    assert len(t) == 2 and len(skipped) == 1 and skipped[0].startswith("line 3: ") and list(t.train_id) == ["T1", "T2"]
    assert read_csv(p, skip_bad_rows=True).equals(t)


def test_separators_and_control_characters_in_a_field_stay_in_their_row(tmp_path):
    """U+2028 is text inside a field, not a line break; a NUL or a line separator in a train id makes
    the pass a rejection with its reason (a C string would cut it); a field past the csv module's
    limit is a malformed row, not a traceback."""
    from rail_monitor.core.passes import rejection_reasons
    from rail_monitor.site_file import load_site

    from conftest import SITE_FILE

    path = tmp_path / "odd.csv"
    head = "time_utc,train_id,vehicle_class,vehicle_count,speed_mps,angle_of_attack_rad,friction_state\n"
    path.write_text(head + "2026-09-01T00:00:00Z,A\u2028B,emu,3,19,0.005,dry\n"
                    + "2026-09-01T00:01:00Z,C\x00D,emu,3,19,0.005,dry\n"
                    + "2026-09-01T00:02:00Z,OK,emu,3,19,0.005,dry\n", encoding="utf-8")
    table = read_csv(path)
    assert table.train_id.tolist() == ["A\u2028B", "C\x00D", "OK"]
    reasons = rejection_reasons(table, load_site(SITE_FILE)).tolist()
    assert reasons == ["train_id has control or separator characters"] * 2 + [""]
    big = tmp_path / "big.csv"
    big.write_text(head + "2026-09-01T00:00:00Z," + "X" * 2**20 + ",emu,3,19,0.005,dry\n")
    with pytest.raises(InputError, match=r"line 2: .*field larger than field limit"):
        read_csv(big)
    assert len(read_csv(big, skip_bad_rows=True)) == 0


def test_a_malformed_row_names_the_way_to_read_the_rest(tmp_path: Path):
    """Issue 52: the one-line refusal of a file with a malformed row says how to go on, and doing
    so reads every other row."""
    p = tmp_path / "one_bad.csv"
    p.write_text(HEADER + ROW + ROW.replace("19.0", "fast") + ROW.replace("T1", "T2"), encoding="utf-8")
    with pytest.raises(InputError) as caught:
        read_csv(p)
    message = str(caught.value)
    assert "line 3: " in message and "--skip-bad-rows" in message and "skip_bad_rows:=true" in message
    assert "\n" not in message
    assert list(read_csv(p, skip_bad_rows=True).train_id) == ["T1", "T2"]
