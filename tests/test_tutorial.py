"""docs/tutorial.md, run as written (issue 24): its commands, and nothing else, on a generated
freight-heavy detector CSV, give the answers the page promises: the grinding date, the list of
squealing trains, and noise percentiles against the limit."""

from __future__ import annotations

import json
import re
import subprocess

import numpy as np
import pandas as pd
import pytest

from rail_monitor.bagio.csv_io import read_csv, write_csv
from rail_monitor.cli import main
from rail_monitor.core.timeutil import format_local_ns
from rail_monitor.report.run_data import load_run

from conftest import TOP

PAGE = TOP / "docs" / "tutorial.md"


def _commands() -> list[str]:
    text = PAGE.read_text()
    block = re.search(r"<!-- tutorial: the job -->\s*```bash\n(.*?)```", text, re.S)
    assert block, "the tutorial's command block is marked '<!-- tutorial: the job -->'"
    return [line for line in block.group(1).splitlines() if line.strip() and not line.startswith("#")]


def _detector_csv(folder):
    """Thirty days of freight-heavy traffic at a 400 m curve, written as a detector would: speed in
    km/h, angle of attack in mrad (the columns of the tutorial's example)."""
    site = folder / "gen.yaml"
    assert main(["site", str(site), "--set", "curve_radius_m=400.0", "--set", "vehicle.freight.traffic_share=0.45",
                 "--set", "vehicle.emu.traffic_share=0.45", "--set", "simulator.days=30.0"]) == 0
    assert main(["simulate", "--site", str(site), "--csv", str(folder / "raw.csv")]) == 0
    raw = pd.read_csv(folder / "raw.csv", comment="#")
    out = pd.DataFrame({"time_utc": raw["time_utc"], "train_id": raw["train_id"],
                        "vehicle_class": raw["vehicle_class"], "vehicle_count": raw["vehicle_count"],
                        "speed_kmh": (raw["speed_mps"] * 3.6).round(2),
                        "angle_of_attack_mrad": (raw["angle_of_attack_rad"] * 1e3).round(3),
                        "friction_state": raw["friction_state"]})
    out.to_csv(folder / "detector.csv", index=False)
    site.unlink()
    (folder / "raw.csv").unlink()
    return out


@pytest.fixture(scope="module")
def job(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tutorial")
    rows = _detector_csv(folder)
    commands = _commands()
    r = subprocess.run(["bash", "-euo", "pipefail", "-c", "\n".join(commands)], cwd=folder, capture_output=True,
                       text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return folder, rows, commands, r.stdout


def test_the_job_is_three_commands_and_no_script(job):
    _, _, commands, _ = job
    assert len(commands) <= 3 and all(c.startswith("rail-monitor ") for c in commands)


def test_the_example_rows_of_the_page_are_a_valid_csv(tmp_path):
    text = PAGE.read_text()
    example = re.search(r"```text\n(time_utc,.*?)```", text, re.S).group(1)
    (tmp_path / "x.csv").write_text(example)
    table = read_csv(tmp_path / "x.csv")
    assert len(table) == 2 and table.speed_mps[0] == pytest.approx(51.7 / 3.6)
    write_csv(table, tmp_path / "y.csv")  # and it round-trips through the canonical columns


def test_grinding_date(job):
    folder, _, _, stdout = job
    run = load_run(folder / "detector_batch")
    summary = json.loads((folder / "detector_batch_report" / "summary.json").read_text())
    due = int(run.states["grinding_due_time"][-1])
    assert due > 0, "the 30-day history forecasts a date"
    assert summary["grinding"]["date"] == format_local_ns(due, "Australia/Brisbane")[:10]
    assert summary["grinding"]["date"] in stdout or format_local_ns(due, "UTC")[:10] in stdout


def test_per_train_squeal_list(job):
    folder, rows, _, _ = job
    run = load_run(folder / "detector_batch")
    trains = pd.read_csv(folder / "detector_batch_report" / "squealing_trains.csv")
    medium_or_above = run.squeal["risk"] >= 2  # RISK_MEDIUM, the site's alerts.squeal_min_risk
    assert len(trains) == int(medium_or_above.sum()) > 0
    assert set(trains["train_id"]) == set(run.squeal["train_id"][medium_or_above])
    assert set(trains["train_id"]) <= set(rows["train_id"])
    assert list(trains["squeal level [dB(A)]"]) == sorted(trains["squeal level [dB(A)]"], reverse=True)


def test_noise_percentiles_against_the_limit(job):
    folder, rows, _, _ = job
    summary = json.loads((folder / "detector_batch_report" / "summary.json").read_text())
    passes = pd.read_excel(folder / "detector_batch_export" / "run.xlsx", sheet_name="passes")
    assert len(passes) == len(rows) and (passes["vehicle_class"] == "freight").mean() > 0.3
    for n in summary["noise"]:
        x = passes[f"{n['model']}_lpafmax_dba"].to_numpy()
        for p in (50, 95):
            assert n[f"P{p} [dB(A)]"] == pytest.approx(np.percentile(x, p), abs=1e-9)
        assert n["above limit [%]"] == pytest.approx(100 * np.mean(x > n["limit [dB(A)]"]), abs=1e-9)
