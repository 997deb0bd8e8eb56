"""rail-monitor batch on a detector export with bad rows (issue 24)."""

from __future__ import annotations

from rail_monitor.bagio.reader import read_bag_passes
from rail_monitor.cli import main

from conftest import EXAMPLE_CSV


def _with_bad_rows(tmp_path):
    lines = EXAMPLE_CSV.read_text().splitlines()
    good = lines[-1].split(",")
    bad_speed = ",".join([*good[:5], "nineteen", *good[6:]])
    bad_time = ",".join(["yesterday", *good[1:]])
    lines[8:8] = [bad_speed, bad_time]
    f = tmp_path / "export.csv"
    f.write_text("\n".join(lines) + "\n")
    return f, len([x for x in EXAMPLE_CSV.read_text().splitlines() if x and not x.startswith(("#", "time"))])


def test_one_bad_row_fails_the_export_naming_its_line(tmp_path, capsys):
    csv, _ = _with_bad_rows(tmp_path)
    assert main(["batch", str(csv), "--output", str(tmp_path / "out"), "--no-report"]) == 2
    assert "line 9: column 'speed_mps'" in capsys.readouterr().err


def test_skip_bad_rows_runs_the_rest_and_names_what_it_left_out(tmp_path, capsys):
    csv, rows = _with_bad_rows(tmp_path)
    out = tmp_path / "out"
    assert main(["batch", str(csv), "--output", str(out), "--no-report", "--skip-bad-rows"]) == 0
    printed = capsys.readouterr().out
    assert "2 malformed row(s)" in printed and "line 9: column 'speed_mps'" in printed and "line 10:" in printed
    assert len(read_bag_passes(out)) == rows  # every good row, none lost
