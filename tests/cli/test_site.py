"""rail-monitor site (issue 24): a new site file with parameters changed, comments kept, checked
by the strict path before it is written; a mistake leaves no file."""

from __future__ import annotations

from rail_monitor.cli import main
from rail_monitor.site_file import load_parameter_file

from conftest import SITE_FILE


def test_a_changed_copy_keeps_the_comments_and_loads(tmp_path, capsys):
    out = tmp_path / "curve_400.yaml"
    assert main(["site", str(out), "--set", "curve_radius_m=400.0", "--set", "vehicle.freight.traffic_share=0.5",
                 "--set", "checkpoint_path=/var/lib/x.npz"]) == 0
    values = load_parameter_file(out)
    shipped = load_parameter_file(SITE_FILE)
    assert values["curve_radius_m"] == 400.0 and values["vehicle.freight.traffic_share"] == 0.5
    assert {k for k in values if values[k] != shipped.get(k)} == {"curve_radius_m", "vehicle.freight.traffic_share"}
    text = out.read_text()
    assert "curve_radius_m: 400.0                # [m]" in text  # the comment stays
    # checkpoint_path is set where the file sets it: corrugation_estimator's own section
    assert text.index("checkpoint_path: \"/var/lib/x.npz\"") > text.index("/**/corrugation_estimator:")
    assert "curve_radius_m: 250.0 -> 400.0" in capsys.readouterr().out


def test_a_mistake_is_one_line_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "bad.yaml"
    for change, why in (("curve_radius_m=400", "write 400 with a decimal point"),
                        ("vehicle.emu.wheel_diamter_m=0.9", "did you mean 'vehicle.emu.wheel_diameter_m'"),
                        ("curve_radius_m", "expected NAME=VALUE"),
                        ("vehicle.dmu.traction=dmuu", "has no traction type 'dmuu'"),
                        ("noise.bridge_constant_db=3.0", "has Table G-7 instead of a bridge constant")):
        assert main(["site", str(out), "--set", change]) == 2
        err = capsys.readouterr().err
        assert why in err and err.count("\n") == 1, err
        assert list(tmp_path.iterdir()) == []
    keep = tmp_path / "mine.yaml"
    keep.write_text("mine")
    assert main(["site", str(keep)]) == 2 and keep.read_text() == "mine"  # never replaced


def test_a_catalogue_file_goes_into_the_site_file_line_for_line(tmp_path, capsys):
    mine = tmp_path / "mine.csv"
    bands = [50, 63, 80, 100, 125, 160, 200, 250, 315, 400, 500, 630, 800, 1000, 1250, 1600, 2000, 2500, 3150, 4000,
             5000, 6300, 8000, 10000]
    rows = "".join(f"{f},{70 + i}.5\n" for i, f in enumerate(bands))
    mine.write_text("# a slab track\nfrequency_hz,track_slab\n" + rows)
    out = tmp_path / "slab.yaml"
    assert main(["site", str(out), "--cnossos-catalogue", str(mine), "--set", "noise.track_transfer=track_slab"]) == 0
    assert load_parameter_file(out)["noise.cnossos_catalogue"] == mine.read_text()
    assert "noise.cnossos_catalogue: 26 lines set" in capsys.readouterr().out
    bad = tmp_path / "bad.csv"
    bad.write_text(mine.read_text().replace("70.5", "seventy"))
    assert main(["site", str(tmp_path / "no.yaml"), "--cnossos-catalogue", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "noise.cnossos_catalogue" in err and "not a number" in err and err.count("\n") == 1, err
    assert not (tmp_path / "no.yaml").exists()
