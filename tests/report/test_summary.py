"""The run report (rail_monitor.report.summary) from a bag batch mode wrote, without a graph run."""

from __future__ import annotations

import pytest

from rail_monitor.bagio.reader import read_passes
from rail_monitor.batch.bag import write_bag
from rail_monitor.batch.run import run_models
from rail_monitor.cli import main
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.report.run_data import load_run
from rail_monitor.report.summary import build_report, summary_lines

from conftest import EXAMPLE_CSV


@pytest.fixture(scope="module")
def bag(tmp_path_factory):
    from rail_monitor.site_file import load_parameter_file

    from conftest import SITE_FILE

    values = load_parameter_file(SITE_FILE)
    result = run_models(read_passes(EXAMPLE_CSV), values)
    return write_bag(result, tmp_path_factory.mktemp("r") / "bag", "curve_250"), values, result


def test_the_summary_states_what_the_bag_holds(bag):
    path, values, result = bag
    run = load_run(path)
    lines = summary_lines(run, SiteConfig.from_values(values))
    assert lines[0].startswith(f"site curve_250: {len(result.passes)} passes from 2026-09-01T")
    assert lines[0].endswith("AEST local)")  # the site's zone, Australia/Brisbane
    assert lines[1] == f"processed {len(result.accepted)}, rejected 0"
    assert any(line.startswith("grinding forecast: worst band") for line in lines)
    assert any(line.startswith("squeal: ") for line in lines)


def test_the_report_folder_has_a_page_and_its_plots(bag, tmp_path):
    path, values, _ = bag
    files = build_report(load_run(path), SiteConfig.from_values(values), tmp_path)
    page = files[-1].read_text()
    assert files[-1].name == "index.html"
    pngs = [f for f in files if f.suffix == ".png"]
    assert [f.stem for f in pngs] == ["timeline", "corrugation", "noise", "squeal", "speeds"]
    for f in files[:-1]:
        assert f.name in page
    for f in pngs:
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_missing_bag_is_one_line_and_exit_2(tmp_path, capsys):
    assert main(["report", str(tmp_path / "missing")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "missing" in err and "Traceback" not in err
