"""The site travels with the data (issue 24): batch and the recorder store the site file in the
bag, twice (an MCAP metadata record per file, metadata.yaml custom_data); report and info read
it; a bag whose copies disagree is refused."""

from __future__ import annotations

import hashlib

import pytest
import yaml
from mcap.reader import make_reader

from rail_monitor.bagio.site_record import SITE_RECORD, read_site_record
from rail_monitor.cli import main
from rail_monitor.cli.common import bag_site_values, site_file
from rail_monitor.core.errors import InputError
from rail_monitor.site_file import load_parameter_file

from conftest import EXAMPLE_CSV


def _curve_400(tmp_path):
    text = site_file(None).read_text().replace("curve_radius_m: 250.0", "curve_radius_m: 400.0")
    text = text.replace('site_id: "curve_250"', 'site_id: "curve_400"')
    path = tmp_path / "curve_400.yaml"
    path.write_text(text)
    assert load_parameter_file(path)["site_id"] == "curve_400"
    return path


@pytest.fixture(scope="module")
def batch_bag(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("site")
    site = _curve_400(tmp)
    csv = tmp / "detector.csv"
    csv.write_text(EXAMPLE_CSV.read_text())
    assert main(["batch", str(csv), "--site", str(site), "--no-report"]) == 0
    return tmp / "detector_batch", site  # next to the input, not in the working folder


def test_batch_stores_the_site_file_in_every_copy(batch_bag):
    bag, site = batch_bag
    text = site.read_text()
    record = read_site_record(bag)
    assert record["site_file"] == text and record["site_file_name"] == "curve_400.yaml"
    assert record["site_file_sha256"] == hashlib.sha256(text.encode()).hexdigest()
    custom = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]["custom_data"]
    assert custom[f"{SITE_RECORD}.site_file"] == text
    (mcap_file,) = bag.glob("*.mcap")
    with open(mcap_file, "rb") as f:  # what any MCAP reader sees
        (meta,) = [m for m in make_reader(f).iter_metadata() if m.name == SITE_RECORD]
    assert meta.metadata["site_file"] == text


def test_report_and_info_use_the_bag_site_and_warn_on_another(batch_bag, capsys):
    bag, site = batch_bag
    assert bag_site_values(bag, None)[0] == load_parameter_file(site)
    assert "curve_400.yaml" in capsys.readouterr().out
    shipped, _ = bag_site_values(bag, str(site_file(None)))  # the user's --site wins, with a warning
    assert shipped["site_id"] == "curve_250"
    err = capsys.readouterr().err
    assert "differs from the site stored" in err and "curve_radius_m" in err
    assert main(["info", str(bag)]) == 0
    assert "site:      curve_400.yaml (sha256" in capsys.readouterr().out


def test_a_bag_whose_copies_disagree_is_refused(batch_bag, tmp_path):
    import shutil

    bag = tmp_path / "copy"
    shutil.copytree(batch_bag[0], bag)
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())
    meta["rosbag2_bagfile_information"]["custom_data"][f"{SITE_RECORD}.site_file_sha256"] = "0" * 64
    (bag / "metadata.yaml").write_text(yaml.safe_dump(meta))
    with pytest.raises(InputError, match="stores another site file"):
        read_site_record(bag)
