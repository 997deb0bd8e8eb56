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


def test_the_summary_counts_what_was_recorded_and_applied(tmp_path, capsys):
    """Issue 52: with one pass stamped 2100 (left out: Time cannot hold it) batch said it recorded
    every pass read; a survey stamped 1969 was refused as "not newer than the last survey" and
    counted as applied. The lines now give what the bag holds and the true reason."""
    import numpy as np

    from rail_monitor.bagio.csv_io import read_csv
    from rail_monitor.bagio.passes_bag import write_passes_bag
    from rail_monitor.core.timeutil import parse_iso_ns
    from rail_monitor.corrugation.surveys import KIND_SURVEY, MaintenanceEvent

    lines = EXAMPLE_CSV.read_text().splitlines()
    rest = lines[-1].split(",", 1)[1]
    (tmp_path / "c.csv").write_text("\n".join([*lines[:-1], "2100-01-01T00:00:00Z," + rest]) + "\n")
    assert main(["batch", str(tmp_path / "c.csv"), "--no-report", "--output", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    held = len(read_bag_passes(tmp_path / "out"))
    read = len(lines) - 1 - sum(1 for line in lines if line.startswith("#"))
    assert held == read - 1
    assert f"batch: {held} passes through the models and recorded" in out and f"; {read} read" in out

    passes = read_csv(EXAMPLE_CSV)
    survey = MaintenanceEvent(parse_iso_ns("1969-12-31T00:00:00Z"), KIND_SURVEY, np.array([0.05]), np.array([1e-6]))
    bag = write_passes_bag(passes, tmp_path / "with_survey", "curve_250", events=[survey])
    assert main(["batch", str(bag), "--no-report", "--output", str(tmp_path / "out2")]) == 0
    out = capsys.readouterr().out
    assert "1 roughness survey(s) and grinding event(s) read: 0 applied in stamp order, 1 refused" in out
    assert "refused: stamp before 1970" in out and "not newer" not in out
