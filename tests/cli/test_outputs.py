"""Output folders (rail_monitor.cli.common.fresh_output): nothing is deleted that the program did not
create; --overwrite replaces only a folder carrying the marker of one rail_monitor wrote."""

from __future__ import annotations

import os

from rail_monitor.bagio.output_folder import MARKER
from rail_monitor.cli import main

from conftest import EXAMPLE_CSV


def _batch(out, *extra) -> list[str]:
    return ["batch", str(EXAMPLE_CSV), "--output", str(out), "--no-report", *extra]


def test_the_working_folder_is_never_replaced(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    keep = tmp_path / "notes.txt"
    keep.write_text("mine")
    (tmp_path / MARKER).write_text("x")  # even marked
    for argv in (_batch(".", "--overwrite"), ["demo", "--source", str(EXAMPLE_CSV), "--output", "."]):
        assert main(argv) == 2
        assert "working folder" in capsys.readouterr().err
    assert keep.read_text() == "mine"


def test_a_folder_the_program_did_not_create_is_left_alone(tmp_path, capsys):
    out = tmp_path / "results"
    out.mkdir()
    (out / "thesis.docx").write_text("mine")
    assert main(_batch(out)) == 2
    assert "pass --overwrite" in capsys.readouterr().err
    assert main(_batch(out, "--overwrite")) == 2
    assert "not created by rail_monitor" in capsys.readouterr().err
    assert (out / "thesis.docx").read_text() == "mine"


def test_a_symlink_or_a_folder_holding_the_input_is_refused(tmp_path, capsys):
    target = tmp_path / "target"
    target.mkdir()
    (target / MARKER).write_text("x")
    link = tmp_path / "link"
    os.symlink(target, link)
    assert main(_batch(link, "--overwrite")) == 2
    assert "symbolic link" in capsys.readouterr().err and target.exists()
    holder = tmp_path / "holder"
    holder.mkdir()
    (holder / MARKER).write_text("x")
    csv = holder / "passes.csv"
    csv.write_bytes(EXAMPLE_CSV.read_bytes())
    assert main(["batch", str(csv), "--output", str(holder), "--no-report", "--overwrite"]) == 2
    assert "holds the input" in capsys.readouterr().err and csv.exists()


def test_a_bag_folder_rail_monitor_wrote_is_replaced_with_overwrite(tmp_path, capsys):
    out = tmp_path / "bag"
    assert main(_batch(out)) == 0 and (out / MARKER).is_file()
    assert main(_batch(out)) == 2
    assert main(_batch(out, "--overwrite")) == 0
    assert (out / "metadata.yaml").exists()
    capsys.readouterr()


def test_a_report_onto_a_full_disk_is_one_line_and_exit_2(tmp_path, tmpfs, capsys):
    disk = tmpfs(100 * 1024)  # room for the first plot, not for all of them
    rc = main(["batch", str(EXAMPLE_CSV), "--output", str(tmp_path / "out"), "--report", str(disk / "rep")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "cannot write the report: No space left on device" in err
