"""rail-monitor simulate for a measured site (rail_monitor.cli.simulate): a true rail's surveys and
a noise station in the bag, which batch then applies, pairs and alerts on."""

from __future__ import annotations

import re

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
