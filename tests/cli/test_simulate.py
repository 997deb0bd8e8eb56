"""rail-monitor simulate for a measured site (rail_monitor.cli.simulate): a true rail's surveys and
a noise station in the bag, which batch then applies, pairs and alerts on."""

from __future__ import annotations

import re

import numpy as np

from rail_monitor.alerts.config import KIND_WHEEL_DEFECT
from rail_monitor.bagio.measured_csv import read_measured_csv
from rail_monitor.bagio.reader import read_bag_events, read_bag_passes, read_measurements, read_messages
from rail_monitor.cli import main


def test_a_measured_site_simulates_into_one_bag_and_batch_names_its_defective_vehicles(tmp_path, capsys):
    bag, station = tmp_path / "site", tmp_path / "station.csv"
    assert main(["simulate", "--days", "20", "--out", str(bag), "--k-b-factor", "3", "--surveys-every-days", "10",
                 "--measured", "--measured-csv", str(station)]) == 0
    out = capsys.readouterr().out
    defective = set(re.search(r"vehicles with wheel flats: (.*)", out).group(1).split(", "))
    passes = read_bag_passes(bag)
    assert len(defective) == 4 and len(read_bag_events(bag)) == 2  # days 0 and 10
    measured = read_measurements(bag)
    assert len(measured) == len(passes) and len(read_measured_csv(station)) == len(measured)
    assert main(["batch", str(bag), "--output", str(tmp_path / "out"), "--no-report"]) == 0
    assert f"{len(measured)} measured pass-by(s) paired with their predictions, 0 refused" in capsys.readouterr().out
    alerts = read_messages(tmp_path / "out", ["rail_msgs/msg/WaysideAlert"])["rail_msgs/msg/WaysideAlert"]
    named = {a.key.removeprefix("vehicle ") for a in alerts if a.kind == KIND_WHEEL_DEFECT and a.active}
    assert defective <= named


def test_a_network_of_curves_with_its_manifest_and_truth(tmp_path, capsys):
    """simulate --network: each curve its own site file (radius, traffic, wet weather drawn), history bag
    and true rail's surveys; the manifest plan reads; truth.csv with the true K_b factor and the true
    rail's due date and cycle, the cycle from a fresh grind beyond the days left of the current one;
    the same seed gives the same network; an existing folder is refused unless --force."""
    import csv

    from rail_monitor.batch.sites import read_manifest
    from rail_monitor.site_file import load_parameter_file

    out = tmp_path / "net"
    args = ["simulate", "--network", "2", "--days", "6", "--surveys-every-days", "2", "--out", str(out)]
    assert main(args) == 0
    assert "wrote 2 curves" in capsys.readouterr().out
    truth = list(csv.DictReader((out / "truth.csv").open()))
    jobs = read_manifest(out / "sites.yaml", checkpoints=True)
    assert [j.site.stem for j in jobs] == [r["site_id"] for r in truth] == ["curve_000", "curve_001"]
    sites = [load_parameter_file(j.site) for j in jobs]
    assert sites[0]["curve_radius_m"] != sites[1]["curve_radius_m"]
    assert sites[0]["simulator.trains_per_hour"] != sites[1]["simulator.trains_per_hour"]
    for job, row in zip(jobs, truth, strict=True):
        assert len(read_bag_passes(job.history)) == int(row["passes"]) > 0
        assert len(read_bag_events(job.history)) == int(row["surveys"]) == 3
        assert 0.3 <= float(row["k_b_factor"]) <= 3.0
        by_state = np.array(row["k_b_by_friction"].split(), float)
        assert len(by_state) == 4 and np.all(by_state > 0) and np.ptp(np.log(by_state)) > 0  # each state its own
        cycles = np.array(row["true_cycle_days"].split(), float)
        assert float(row["true_due_days"]) > 0 and len(set(cycles)) == 12 and np.all(cycles > 0)
    assert main(args) == 2
    assert "exists" in capsys.readouterr().err
    assert main([*args, "--force"]) == 0
    assert list(csv.DictReader((out / "truth.csv").open())) == truth
