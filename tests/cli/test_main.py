"""The command line in-process (rail_monitor.cli.main): verbs return their exit code, errors are one
line, the installed entry point is the same function."""

from __future__ import annotations

import pytest

from rail_monitor.bagio.csv_io import read_csv
from rail_monitor.cli import main

from conftest import SAMPLE, run_cmd


def test_info_summarises_the_sample(capsys):
    assert main(["info", str(SAMPLE)]) == 0
    out = capsys.readouterr().out
    assert "passes:    8638 (96.2 per day)" in out and "classes:   dmu" in out


def test_simulate_writes_a_csv_that_reads_back(tmp_path, capsys):
    csv = tmp_path / "p.csv"
    assert main(["simulate", "--days", "1", "--seed", "3", "--csv", str(csv)]) == 0
    assert capsys.readouterr().out.startswith("wrote ")
    assert len(read_csv(csv)) > 50
    assert main(["simulate", "--days", "1"]) == 2
    assert "give --out BAG and/or --csv FILE" in capsys.readouterr().err


def test_a_site_file_with_a_typo_is_one_line_and_exit_2(tmp_path, capsys):
    site = tmp_path / "site.yaml"
    site.write_text("/**:\n  ros__parameters:\n    curve_radius: 300.0\n")
    assert main(["predict", "corrugation", "--site", str(site)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "did you mean 'curve_radius_m'" in err


def test_usage_errors_are_argparse_exits():
    with pytest.raises(SystemExit) as e:
        main(["no-such-verb"])
    assert e.value.code == 2


def test_the_installed_entry_point_runs_the_same_main():
    r = run_cmd("rail-monitor", "predict", "squeal", "--rig", "--crabbing", "0.39")
    assert r.returncode == 0 and "the paper's rig (Figure 5)" in r.stdout


def test_every_option_states_its_default_once():
    """--help of every verb: no option says its default twice (its own text and argparse's)."""
    import argparse

    from rail_monitor.cli import build_parser

    def parsers(p):
        yield p
        for a in p._actions:
            if isinstance(a, argparse._SubParsersAction):
                for sub in a.choices.values():
                    yield from parsers(sub)

    checked = 0
    for p in parsers(build_parser()):
        formatter = p._get_formatter()
        for a in p._actions:
            if a.help and a.option_strings:
                text = formatter._expand_help(a)
                assert text.count("default") <= 1, f"{p.prog} {a.option_strings[0]}: {text}"
                checked += 1
    assert checked > 100
