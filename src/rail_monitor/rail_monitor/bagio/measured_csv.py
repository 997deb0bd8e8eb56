"""CSV export of a wayside noise station: one measured pass-by per row, units in the column names.

    quantity              columns (unit)                                        required
    time                  time_utc (ISO 8601), time_unix_s, time_unix_ns        yes (the pass's stamp)
    train_id              train_id                                              yes
    receiver              receiver_distance_m, receiver_height_m                yes
    instrument            instrument_class (1 or 2, IEC 61672-1)                yes
    single numbers        lpaeq_tp_dba, lpafmax_dba, tel_dba                    yes
    band levels           leq_<centre>hz_db, e.g. leq_50hz_db ... leq_10000hz_db  at least one
    squeal                squeal_detected (true/false, 1/0, yes/no)             no (false)
    squeal measured       squeal_frequency_hz, squeal_level_db (dB re 20 uPa),   no (not measured;
                          squeal_duration_s; flanging_detected (true/false)     an empty cell too)
    vehicle segments      vehicle_lpaeq_dba: id=level;id=level, running order   no

Lines starting with '#' are comments; columns not in the table are ignored. A row that does not
parse is an error naming its line (or, with skip_bad_rows, left out and counted); a row that
parses but is unusable (a NaN band, an absurd level) is read, and refused with its reason where
it is paired (rail_monitor.measured), so nothing is dropped unseen.
"""

from __future__ import annotations

import csv
import io
import re
from pathlib import Path

import numpy as np

from rail_monitor.bagio.csv_io import SKIP_HINT, TIME_COLUMNS, csv_cells, csv_lines
from rail_monitor.core.errors import InputError, RailMonitorError
from rail_monitor.core.timeutil import format_iso_ns
from rail_monitor.measured.records import SQUEAL_MEASURES, Measurement

_BAND = re.compile(r"^leq_(\d+(?:\.\d+)?)hz_db$")
_REQUIRED = ("train_id", "receiver_distance_m", "receiver_height_m", "instrument_class", "lpaeq_tp_dba",
             "lpafmax_dba", "tel_dba")
_TRUE, _FALSE = {"true", "1", "yes"}, {"false", "0", "no", ""}


def _flag(text: str) -> bool:
    t = text.strip().lower()
    if t in _TRUE | _FALSE:
        return t in _TRUE
    raise ValueError(f"{text!r} is not true/false")


def _cell(value: float | bool) -> str:
    """A squeal measure's cell: true/false, a number, or empty for not measured (NaN)."""
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    return "" if np.isnan(value) else repr(float(value))


def _segments(text: str) -> tuple[tuple[str, ...], np.ndarray]:
    pairs = [p.rsplit("=", 1) for p in text.split(";") if p.strip()]
    if any(len(p) != 2 for p in pairs):
        raise ValueError(f"{text!r} is not id=level;id=level")
    return tuple(p[0].strip() for p in pairs), np.array([float(p[1]) for p in pairs])


def read_measured_csv(path: str | Path, skip_bad_rows: bool = False) -> list[Measurement]:
    """The measurements of a noise station's CSV, in file order (skipped rows: the list's length
    against the data lines; each reason in the returned list's ``skipped_rows``)."""
    path = Path(path)
    header_line, header, lines = csv_lines(path, "time_utc,train_id,lpaeq_tp_dba,leq_50hz_db,...")
    col = {name: i for i, name in enumerate(header)}
    times = [c for c in header if c in TIME_COLUMNS]
    bands = [(float(m.group(1)), i) for i, c in enumerate(header) if (m := _BAND.match(c))]
    missing = [c for c in _REQUIRED if c not in col] + ([] if times else [" or ".join(TIME_COLUMNS)])
    missing += [] if bands else ["leq_<centre>hz_db (one per band)"]
    if missing:
        raise InputError(f"{path}: missing column(s): {'; '.join(missing)}")
    if len(times) > 1:
        raise InputError(f"{path}: line {header_line}: columns {times[0]!r} and {times[1]!r} give the same quantity")
    centre = np.array([f for f, _ in bands])
    out: list[Measurement] = []
    skipped: list[str] = []
    for n, line in lines:
        try:
            cells = csv_cells(line, header)

            def num(name: str, c: list[str] = cells) -> float:
                try:
                    return float(c[col[name]])
                except ValueError:
                    raise ValueError(f"column {name!r}: {c[col[name]]!r} is not a number") from None

            ids, levels = _segments(cells[col["vehicle_lpaeq_dba"]]) if "vehicle_lpaeq_dba" in col else ((), None)
            squeal: dict[str, float | bool] = {}  # an empty cell: not measured
            for name, default in SQUEAL_MEASURES.items():
                if name in col and cells[col[name]].strip():
                    squeal[name] = _flag(cells[col[name]]) if isinstance(default, bool) else num(name)
            out.append(Measurement(
                TIME_COLUMNS[times[0]](cells[col[times[0]]].strip()), cells[col["train_id"]].strip(),
                num("receiver_distance_m"), num("receiver_height_m"), int(num("instrument_class")), centre.copy(),
                np.array([float(cells[i]) for _, i in bands]), num("lpaeq_tp_dba"), num("lpafmax_dba"),
                num("tel_dba"), _flag(cells[col["squeal_detected"]]) if "squeal_detected" in col else False,
                ids, levels if levels is not None else np.zeros(0), **squeal))
        except (ValueError, RailMonitorError) as exc:
            if not skip_bad_rows:
                raise InputError(f"{path}: line {n}: {exc}{SKIP_HINT}") from None
            skipped.append(f"line {n}: {exc}")
    result = _Measurements(out)
    result.skipped_rows = skipped
    return result


class _Measurements(list):
    """A list of measurements that says which rows were skipped."""

    skipped_rows: list[str]


def write_measured_csv(measurements: list[Measurement], path: str | Path) -> None:
    """Write measurements (all on the same bands) in the documented layout (lossless)."""
    if not measurements:
        raise RailMonitorError("no measurements to write")
    bands = measurements[0].band_centre_hz
    buf = io.StringIO()
    buf.write("# Measured pass-by noise at a wayside site (rail_monitor CSV). One row per pass; levels in dB\n"
              "# re 20 uPa, A-weighted single numbers in dB(A); vehicle_lpaeq_dba: id=level;... in running order.\n")
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["time_utc", *_REQUIRED, "squeal_detected", *SQUEAL_MEASURES, *(f"leq_{f:g}hz_db" for f in bands),
                "vehicle_lpaeq_dba"])
    for m in measurements:
        if not np.array_equal(m.band_centre_hz, bands):
            raise RailMonitorError("measurements on different bands cannot share one CSV")
        w.writerow([format_iso_ns(m.stamp_ns), m.train_id, repr(m.receiver_distance_m), repr(m.receiver_height_m),
                    m.instrument_class, repr(m.lpaeq_tp_dba), repr(m.lpafmax_dba), repr(m.tel_dba),
                    "true" if m.squeal_detected else "false", *(_cell(getattr(m, name)) for name in SQUEAL_MEASURES),
                    *(repr(float(x)) for x in m.leq_db),
                    ";".join(f"{v}={float(x)!r}" for v, x in zip(m.vehicle_id, m.vehicle_lpaeq_dba, strict=True))])
    Path(path).write_text(buf.getvalue(), encoding="utf-8")
