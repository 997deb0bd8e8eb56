"""Text from files on its way to a terminal or a report: control characters shown as escapes."""

from __future__ import annotations

from rail_monitor.cli import main
from rail_monitor.core.text import printable

from conftest import EXAMPLE_CSV


def test_controls_separators_and_bidi_overrides_are_escaped_letters_kept():
    assert printable("\x1b[2J\x07bell\x00\x7f") == "\\x1b[2J\\x07bell\\x00\\x7f"
    assert printable("a\u2028b\u2029c\u202ed\u0085") == "a\\u2028b\\u2029c\\u202ed\\x85"
    assert printable("\udcff") == "\\udcff"  # an undecodable byte (surrogateescape)
    for kept in ("Zürich S-Bahn", "Œ 東京 \u00a0 ü", "EMU-000194", "🚆"):
        assert printable(kept) == kept


def _csv_with(tmp_path, cls: str):
    text = EXAMPLE_CSV.read_text()
    row = text.strip().splitlines()[-1].split(",")
    row[2] = cls
    f = tmp_path / "p.csv"
    f.write_text(text + ",".join(row) + "\n", encoding="utf-8")
    return f


def test_info_shows_a_vehicle_class_with_escapes_as_escapes(tmp_path, capsys):
    assert main(["info", str(_csv_with(tmp_path, "emu\x1b[2J\u202e"))]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\u202e" not in out and "emu\\x1b[2J\\u202e 1" in out


def test_an_error_line_naming_a_hostile_value_is_inert(tmp_path, capsys):
    csv = _csv_with(tmp_path, "emu")
    csv.write_text(csv.read_text().replace(",dry,", ",\x1b]0;pwned\x07,", 1), encoding="utf-8")
    assert main(["info", str(csv)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "\x1b" not in err and "\x07" not in err and "\\x1b]0;pwned\\x07" in err
