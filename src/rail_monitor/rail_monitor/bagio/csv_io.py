"""CSV export of a wayside detector: documented columns with units in the header.

One row per train pass; lines starting with '#' are comments. A column's name is the quantity
followed by its unit; the accepted names and their conversion to SI are the table below, so a
file in km/h or mrad reads correctly and a file in an unknown unit is refused by name.

    quantity              accepted columns (unit)                          required
    time                  time_utc (ISO 8601), time_unix_s, time_unix_ns   yes
    train_id              train_id                                         yes
    vehicle_class         vehicle_class                                    yes
    vehicle_count         vehicle_count                                    one of the two
    axle_count            axle_count                                       one of the two
    speed                 speed_mps, speed_kmh                             yes
    angle_of_attack       angle_of_attack_rad, angle_of_attack_mrad        yes
    wheel_load            wheel_load_n, wheel_load_kn                      no (0: class value)
    friction_state        dry, wet, friction_modifier, contaminated        yes
    train_length          train_length_m                                   no (0: from the class)
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from pathlib import Path

from rail_monitor.core.errors import InputError, RailMonitorError
from rail_monitor.core.passes import FRICTION_BY_NAME, FRICTION_NAMES, KMH_PER_MPS, PassTable
from rail_monitor.core.timeutil import NS_PER_S, checked_ns, format_iso_ns, parse_iso_ns
from rail_monitor.core.user_file import MAX_TABLE_BYTES, read_user_text


def time_utc(text: str) -> int:
    return parse_iso_ns(text)


def time_unix_s(text: str) -> int:
    seconds = float(text)
    if not math.isfinite(seconds):
        raise ValueError(f"{text!r} is not a finite time")
    return checked_ns(round(seconds * NS_PER_S))


def time_unix_ns(text: str) -> int:
    return checked_ns(int(text))


def _friction(text: str) -> int:
    try:
        return FRICTION_BY_NAME[text.strip().lower()]
    except KeyError:
        raise ValueError(f"unknown friction state {text!r} (use {', '.join(FRICTION_BY_NAME)})") from None


def _count(text: str) -> int:
    value = int(text)
    if value < 0 or value > 65535:
        raise ValueError(f"{value} is outside 0-65535")
    return value


TIME_COLUMNS: dict[str, Callable[[str], int]] = {"time_utc": time_utc, "time_unix_s": time_unix_s,
                                                  "time_unix_ns": time_unix_ns}


def _scaled(factor: float) -> Callable[[str], float]:
    return lambda text: float(text) * factor


# quantity -> {column name: parser to the PassTable column's SI value}; None marks "optional".
_QUANTITIES: dict[str, tuple[str, dict[str, Callable[[str], object]], object]] = {
    "time": ("stamp_ns", TIME_COLUMNS, None),
    "train_id": ("train_id", {"train_id": str}, None),
    "vehicle_class": ("vehicle_class", {"vehicle_class": str}, None),
    "vehicle_count": ("vehicle_count", {"vehicle_count": _count}, 0),
    "axle_count": ("axle_count", {"axle_count": _count}, 0),
    "speed": ("speed_mps", {"speed_mps": float, "speed_kmh": _scaled(1.0 / KMH_PER_MPS)}, None),
    "angle_of_attack": ("angle_of_attack_rad",
                        {"angle_of_attack_rad": float, "angle_of_attack_mrad": _scaled(1.0e-3)}, None),
    "wheel_load": ("wheel_load_n", {"wheel_load_n": float, "wheel_load_kn": _scaled(1.0e3)}, 0.0),
    "friction_state": ("friction_state", {"friction_state": _friction}, None),
    "train_length": ("train_length_m", {"train_length_m": float}, 0.0),
}


def _quantity_of(column: str) -> str | None:
    for q in sorted(_QUANTITIES, key=len, reverse=True):
        if column == q or column.startswith(q + "_"):
            return q
    return None



def csv_lines(path: Path, expected: str) -> tuple[int, list[str], list[tuple[int, str]]]:
    """A CSV file's header (its line number and stripped column names) and its data lines (line
    number, text), comments and blank lines left out; InputError without a header (expected: the
    columns to name in that error)."""
    text = read_user_text(path, "a CSV", MAX_TABLE_BYTES)
    # Lines end at \n alone (str.splitlines would also split at U+2028 and other separators inside a field).
    lines = [(n, line.removesuffix("\r")) for n, line in enumerate(text.split("\n"), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise InputError(f"{path}: no header line (expected columns such as {expected})")
    try:
        header = next(csv.reader([lines[0][1]]))
    except csv.Error as exc:
        raise InputError(f"{path}: line {lines[0][0]}: {exc}") from None
    return lines[0][0], [h.strip() for h in header], lines[1:]


def csv_cells(line: str, header: list[str]) -> list[str]:
    """The fields of a data line; ValueError when they do not match the header."""
    try:
        cells = next(csv.reader([line]))
    except csv.Error as exc:
        raise ValueError(str(exc)) from None
    if len(cells) != len(header):
        raise ValueError(f"{len(cells)} fields where the header has {len(header)}")
    return cells


SKIP_HINT = ("; to read the rest, leave malformed rows out with rail-monitor batch --skip-bad-rows "
             "(pass_replayer: skip_bad_rows:=true)")


def read_csv(path: str | Path, skip_bad_rows: bool = False) -> PassTable:
    """Read a detector CSV. A malformed row is an error naming its line, unless skip_bad_rows
    (then it is left out; read_csv_rows says which)."""
    return read_csv_rows(path, skip_bad_rows)[0]


def read_csv_rows(path: str | Path, skip_bad_rows: bool = False) -> tuple[PassTable, list[str]]:
    """read_csv, with each row left out under skip_bad_rows as "line N: reason"."""
    path = Path(path)
    header_line, header, lines = csv_lines(path, "time_utc,train_id,...")
    parsers: dict[int, tuple[str, Callable[[str], object]]] = {}
    seen: dict[str, str] = {}
    for i, col in enumerate(header):
        q = _quantity_of(col)
        if q is None:
            continue  # extra columns of a detector export are allowed and ignored
        target, accepted, _ = _QUANTITIES[q]
        if col not in accepted:
            raise InputError(f"{path}: line {header_line}: column {col!r} has a unit this reader does not "
                             f"accept; use one of {', '.join(accepted)}")
        if q in seen:
            raise InputError(f"{path}: line {header_line}: columns {seen[q]!r} and {col!r} give the same quantity")
        seen[q] = col
        parsers[i] = (target, accepted[col])
    missing = [q for q, (_, acc, default) in _QUANTITIES.items() if default is None and q not in seen]
    if missing:
        names = "; ".join(" or ".join(_QUANTITIES[q][1]) for q in missing)
        raise InputError(f"{path}: missing column(s): {names}")
    if "vehicle_count" not in seen and "axle_count" not in seen:
        raise InputError(f"{path}: missing column: vehicle_count or axle_count")

    rows, why = [], []
    for n, line in lines:
        try:
            cells = csv_cells(line, header)
            row = {target: default for _, (target, _, default) in _QUANTITIES.items()}
            for i, (target, parse) in parsers.items():
                try:
                    row[target] = parse(cells[i].strip())
                except (ValueError, RailMonitorError) as exc:
                    raise ValueError(f"column {header[i]!r}: {exc}") from None
            rows.append(row)
        except ValueError as exc:
            if not skip_bad_rows:
                raise InputError(f"{path}: line {n}: {exc}{SKIP_HINT}") from None
            why.append(f"line {n}: {exc}")
    return PassTable.from_rows(rows), why


CSV_HEADER_COMMENT = """\
# Train passes at a wayside site (rail_monitor CSV). One row per pass.
# time_utc: ISO 8601 UTC; speed_mps [m/s]; angle_of_attack_rad [rad]; wheel_load_n [N] (0: class value);
# train_length_m [m] (0: from the class); friction_state: dry | wet | friction_modifier | contaminated
"""


def write_csv(table: PassTable, path: str | Path) -> None:
    """Write passes in the documented layout (SI columns, ISO times with ns; lossless)."""
    buf = io.StringIO()
    buf.write(CSV_HEADER_COMMENT)
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["time_utc", "train_id", "vehicle_class", "vehicle_count", "axle_count", "speed_mps",
                "angle_of_attack_rad", "wheel_load_n", "friction_state", "train_length_m"])
    for i in range(len(table)):
        r = table.row(i)
        w.writerow([format_iso_ns(r["stamp_ns"]), r["train_id"], r["vehicle_class"], r["vehicle_count"],
                    r["axle_count"], repr(r["speed_mps"]), repr(r["angle_of_attack_rad"]), repr(r["wheel_load_n"]),
                    FRICTION_NAMES.get(r["friction_state"], str(r["friction_state"])), repr(r["train_length_m"])])
    Path(path).write_text(buf.getvalue(), encoding="utf-8")


