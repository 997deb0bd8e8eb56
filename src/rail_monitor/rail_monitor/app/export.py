"""Tables of a recorded run for analysis elsewhere: one row per pass with every model output, and
one row per alert event; written as CSV, Parquet or an Excel workbook.

Outputs are joined to their pass by (train_id, pass stamp), as the graph stamps every output with
its pass's time. The corrugation columns are the state after the pass: the newest state recorded
at or before the pass time. Units are in the column names (as in the pass CSV) and, in Parquet,
in each field's metadata (``unit``, ``description``), with the site and software version in the
schema metadata.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor.alerts.config import KIND_NAMES, RISK_NAMES
from rail_monitor.app.report import RunData
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.passes import FRICTION_NAMES, KMH_PER_MPS, rejection_reasons
from rail_monitor.core.site import site_from_values
from rail_monitor.core.timeutil import format_iso_ns, format_local_ns
from rail_monitor.models.squeal import REGIME_NAMES
from rail_monitor.noise.predict import INCREASE_REFERENCE

FORMATS = ("csv", "parquet", "xlsx")
SEVERITY_NAMES = ("info", "warning", "critical")


@dataclass(frozen=True)
class Column:
    name: str
    unit: str
    description: str
    values: np.ndarray


@dataclass(frozen=True)
class Table:
    name: str
    columns: list[Column]

    def as_dict(self) -> dict[str, np.ndarray]:
        return {c.name: c.values for c in self.columns}


def _lookup(keys: list[tuple[str, int]], of: list[tuple[str, int]]) -> np.ndarray:
    """Index into `of` of each key (-1 where a pass has no such output)."""
    where = {k: i for i, k in enumerate(of)}
    return np.array([where.get(k, -1) for k in keys], np.int64)


def _pick(values: np.ndarray, index: np.ndarray, fill: Any = np.nan) -> np.ndarray:
    """values[index], fill where index is -1 (float columns get NaN there, and for a non-finite value:
    'none' or 'never', an empty cell), others the fill."""
    values = np.asarray(values)
    numeric = values.dtype.kind in "fc"
    if numeric:
        values = np.where(np.isfinite(values), values, np.nan)
    out = np.full(len(index), np.nan) if numeric else np.full(len(index), fill, dtype=object)
    ok = index >= 0
    out[ok] = values[index[ok]]
    return out


def pass_table(run: RunData, values: Mapping[str, Any]) -> Table:
    """One row per recorded pass: the pass, its validation, and every model output for it."""
    site = site_from_values(values)
    p = run.passes
    zone = site.time_zone
    keys = list(zip(p.train_id.tolist(), p.stamp_ns.tolist(), strict=True))
    reasons = rejection_reasons(p, site)
    cols = [
        Column("time_utc", "ISO 8601", "pass time (UTC, ns resolution)", np.array([format_iso_ns(t) for t in
                                                                                   p.stamp_ns.tolist()], object)),
        Column("time_local", zone, f"pass time in the site's zone ({zone})",
               np.array([format_local_ns(t, zone, seconds=True) for t in p.stamp_ns.tolist()], object)),
        Column("stamp_ns", "ns", "pass time, ns since the Unix epoch", p.stamp_ns),
        Column("train_id", "-", "train identifier", p.train_id),
        Column("vehicle_class", "-", "vehicle class", p.vehicle_class),
        Column("vehicle_count", "-", "vehicles in the consist", p.vehicle_count),
        Column("axle_count", "-", "axles in the consist", p.axle_count),
        Column("speed_mps", "m/s", "train speed", p.speed_mps),
        Column("speed_kmh", "km/h", "train speed", p.speed_mps * KMH_PER_MPS),
        Column("angle_of_attack_mrad", "mrad", "angle of attack of the leading wheelset", 1e3 * p.angle_of_attack_rad),
        Column("friction_state", "-", "friction state", np.array([FRICTION_NAMES.get(int(f), str(f))
                                                                  for f in p.friction_state], object)),
        Column("status", "-", "'processed', or why the models rejected the pass",
               np.array([r or "processed" for r in reasons.tolist()], object)),
    ]
    sq = run.squeal
    if len(sq.get("train_id", ())):
        i = _lookup(keys, list(zip(sq["train_id"].tolist(), sq["stamp_ns"].tolist(), strict=True)))
        risk = np.array(RISK_NAMES, object)[sq["risk"].astype(int)]
        regime = np.array([REGIME_NAMES[int(r)] for r in sq["regime"]], object)
        cols += [Column(f"squeal_{name}", unit, text, _pick(v, i, "")) for name, unit, text, v in (
            ("risk", "-", "squeal risk class", risk),
            ("regime", "-", "squeal regime", regime),
            ("level_dba", "dB(A)", "squeal sound pressure level at the receiver (empty: no squeal)", sq["level_dba"]),
            ("amplitude_mps", "m/s", "lateral wheel velocity amplitude A w", sq["velocity_amplitude_mps"]),
            ("crabbing_velocity_mps", "m/s", "crabbing velocity Vc", sq["crabbing_velocity_mps"]),
            ("frequency_hz", "Hz", "squeal frequency", sq["frequency_hz"]),
            ("friction_modifier_benefit_db", "dB", "predicted reduction with a friction modifier",
             sq["friction_modifier_benefit_db"]))]
    for model, nz in run.noise.items():
        i = _lookup(keys, list(zip(nz["train_id"].tolist(), nz["stamp_ns"].tolist(), strict=True)))
        cols += [
            Column(f"{model}_lpaeq_tp_dba", "dB(A)", f"rolling noise ({model}): LpAeq,Tp at the receiver",
                   _pick(nz["lpaeq_tp_dba"], i)),
            Column(f"{model}_lpafmax_dba", "dB(A)", f"rolling noise ({model}): LpAFmax at the receiver",
                   _pick(nz["lpafmax_dba"], i)),
            Column(f"{model}_tel_dba", "dB(A)", f"rolling noise ({model}): transit exposure level (ISO 3095)",
                   _pick(nz["tel_dba"], i)),
            Column(f"{model}_increase_since_grinding_db", "dB", f"rolling noise ({model}): LpAeq,Tp minus "
                   f"{INCREASE_REFERENCE}", _pick(nz["roughness_growth_increase_db"], i)),
        ]
    cols += _measured_columns(run, keys)
    cols += _state_columns(run, p.stamp_ns)
    return Table("passes", cols)


def _measured_columns(run: RunData, keys: list[tuple[str, int]]) -> list[Column]:
    """The measured pass-by and its residual per model (empty where a pass was not measured)."""
    cols = []
    if len(run.measured.get("train_id", ())):
        m = run.measured
        i = _lookup(keys, list(zip(m["train_id"].tolist(), m["stamp_ns"].tolist(), strict=True)))
        cols += [Column(f"measured_{name}", unit, text, _pick(m[name], i, "")) for name, unit, text in (
            ("lpaeq_tp_dba", "dB(A)", "measured LpAeq,Tp"), ("lpafmax_dba", "dB(A)", "measured LpAFmax"),
            ("tel_dba", "dB(A)", "measured TEL"), ("squeal_detected", "-", "the station's squeal flag"))]
    for model, r in run.residuals.items():
        i = _lookup(keys, list(zip(r["train_id"].tolist(), r["stamp_ns"].tolist(), strict=True)))
        cols += [Column(f"{model}_{name}", unit, f"measured minus predicted ({model}): {text}", _pick(r[name], i, ""))
                 for name, unit, text in (
                     ("residual_lpaeq_dba", "dB(A)", "LpAeq,Tp"),
                     ("residual_mid_db", "dB", "energy sum of the 500-2000 Hz bands"),
                     ("baseline_mid_db", "dB", "the site's running median of the 500-2000 Hz residual before the pass"),
                     ("excess_mid_db", "dB", "500-2000 Hz residual over the baseline (wheel-defect score)"),
                     ("loudest_vehicle_id", "-", "the vehicle segment loudest above its train's mean"),
                     ("loudest_vehicle_excess_db", "dB(A)", "its LpAeq over the train's energy mean"))]
    return cols


def _state_columns(run: RunData, stamps: np.ndarray) -> list[Column]:
    s = run.states
    if not s:
        return []
    k = np.searchsorted(s["stamp"], stamps, side="right") - 1  # the newest state at or before the pass
    worst = s["worst_band"].astype(int)
    rows = np.arange(len(worst))
    cols = [Column(f"corrugation_{name}", unit, text, _pick(v, k, None)) for name, unit, text, v in (
        ("worst_wavelength_mm", "mm", "wavelength of the band nearest its threshold", 1e3 * s["wavelength_m"][worst]),
        ("worst_rms_um", "µm", "r.m.s. corrugation of that band", 1e6 * s["amplitude_m"][rows, worst]),
        ("days_to_threshold", "d", "forecast days until that band reaches its threshold (empty: never)",
         s["days_to_threshold"]),
        ("grinding_due", "-", "a band is at or past its threshold", s["grinding_due"].astype(object)))]
    for b, lam in enumerate(s["wavelength_m"]):
        cols.append(Column(f"corrugation_rms_um_{1e3 * lam:.4g}mm", "µm", f"r.m.s. corrugation, {1e3 * lam:.4g} mm "
                           "band", _pick(1e6 * s["amplitude_m"][:, b], k)))
    return cols


def alert_table(run: RunData, values: Mapping[str, Any]) -> Table:
    """One row per alert event (a raise or a clear), in pass-time order."""
    zone = site_from_values(values).time_zone
    a = run.alerts
    col = lambda f: np.array([f(x) for x in a], object)  # noqa: E731
    return Table("alerts", [
        Column("time_utc", "ISO 8601", "pass time of the event (UTC)", col(lambda x: format_iso_ns(x.stamp_ns))),
        Column("time_local", zone, f"pass time of the event ({zone})",
               col(lambda x: format_local_ns(x.stamp_ns, zone, seconds=True))),
        Column("stamp_ns", "ns", "pass time of the event, ns since the Unix epoch",
               np.array([x.stamp_ns for x in a], np.int64)),
        Column("event", "-", "raised or cleared", col(lambda x: "raised" if x.active else "cleared")),
        Column("kind", "-", "alert kind", col(lambda x: KIND_NAMES.get(x.kind, str(x.kind)))),
        Column("key", "-", "what the alert is about (a band, a model, a train)", col(lambda x: x.key)),
        Column("severity", "-", "severity", col(lambda x: SEVERITY_NAMES[x.severity] if 0 <= x.severity < 3 else "")),
        Column("value", "see unit", "the value that raised or cleared it", np.array([x.value for x in a], float)),
        Column("threshold", "see unit", "its limit", np.array([x.threshold for x in a], float)),
        Column("unit", "-", "unit of value and threshold", col(lambda x: x.unit)),
        Column("summary", "-", "the alert's text", col(lambda x: x.summary)),
    ])


# -- writing ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Written:
    """What an export wrote: (table name, rows, columns) per table, the files, and lines for the user."""

    tables: list[tuple[str, int, int]]
    files: list[Path]
    notes: list[str]


def export_run(bag: str | Path, values: Mapping[str, Any], fmt: str, folder: Path,
               schema_metadata: Mapping[str, str], chunk: int = 5_000) -> Written:
    """The pass and alert tables of a recorded run written into folder (a new, empty one).

    CSV and Parquet of a bag rail_monitor recorded are written ``chunk`` passes at a time
    (memory: one part, whatever the run's length); Excel, chunk 0, or another bag are read whole.
    """
    from rail_monitor.app.report import NotStampOrdered, load_run

    notes: list[str] = []
    if fmt in ("csv", "parquet") and chunk > 0:
        try:
            return _export_in_parts(bag, values, fmt, folder, schema_metadata, chunk)
        except (NotStampOrdered, ColumnsChanged) as exc:
            for name in ("passes", "alerts"):  # the parts written so far: this export's own files
                (folder / f"{name}.{fmt}").unlink(missing_ok=True)
            notes.append(f"{exc}; read whole instead")
    run = load_run(bag)
    tables = [pass_table(run, values), alert_table(run, values)]
    files = write_tables(tables, fmt, folder, schema_metadata)
    return Written([(t.name, len(t.columns[0].values), len(t.columns)) for t in tables], files, notes)


def _export_in_parts(bag: str | Path, values: Mapping[str, Any], fmt: str, folder: Path,
                     schema_metadata: Mapping[str, str], chunk: int) -> Written:
    from rail_monitor.app.report import iter_runs

    passes = TableSink("passes", fmt, folder, schema_metadata)
    alerts: list[Any] = []
    last: RunData | None = None
    for part in iter_runs(bag, chunk):
        passes.add(pass_table(part, values))
        alerts += part.alerts
        last = part
    assert last is not None  # iter_runs gives at least one part or raises
    last.alerts = sorted(alerts, key=lambda a: (a.stamp_ns, a.kind, a.key, a.active))
    table = alert_table(last, values)
    events = TableSink("alerts", fmt, folder, schema_metadata)
    events.add(table)
    files = [passes.close(), events.close()]
    return Written([("passes", passes.rows, len(passes.names or ())), ("alerts", events.rows, len(table.columns))],
                   files, [])

def write_tables(tables: list[Table], fmt: str, folder: Path, schema_metadata: Mapping[str, str]) -> list[Path]:
    """Write each table into folder as <name>.csv or <name>.parquet, or all as sheets of
    run.xlsx (with a 'columns' sheet of units and descriptions); returns the files written."""
    if fmt not in FORMATS:
        raise RailMonitorError(f"export format must be one of {', '.join(FORMATS)}, not {fmt!r}")
    try:
        if fmt == "parquet":
            return [_parquet(t, folder / f"{t.name}.parquet", schema_metadata) for t in tables]
        frames = {t.name: _frame(t, excel=fmt == "xlsx") for t in tables}
        if fmt == "csv":
            for name, df in frames.items():
                df.to_csv(folder / f"{name}.csv", index=False)
            return [folder / f"{name}.csv" for name in frames]
        import pandas as pd

        path = folder / "run.xlsx"
        units = pd.DataFrame([{"sheet": t.name, "column": c.name, "unit": c.unit, "description": c.description}
                              for t in tables for c in t.columns])
        with pd.ExcelWriter(path, engine="openpyxl") as xl:
            for name, df in frames.items():
                df.to_excel(xl, sheet_name=name, index=False)
            units.to_excel(xl, sheet_name="columns", index=False)
            pd.DataFrame(sorted(schema_metadata.items()), columns=["key", "value"]).to_excel(
                xl, sheet_name="about", index=False)
        return [path]
    except OSError as exc:
        raise RailMonitorError(f"{folder}: cannot write the export: {exc.strerror or exc}") from None


def _frame(t: Table, excel: bool):
    """The table as a DataFrame; for Excel, whose numbers are doubles, integers beyond 2^53 (the ns
    stamps) as text so that none is rounded."""
    import pandas as pd

    data = t.as_dict()
    if excel:
        data = {k: v.astype(str) if v.dtype.kind == "i" and np.abs(v).max(initial=0) > 2**53 else v
                for k, v in data.items()}
    return pd.DataFrame(data)


def _arrow(t: Table, schema_metadata: Mapping[str, str]):
    import pyarrow as pa

    arrays, fields = [], []
    for c in t.columns:
        v = c.values
        arr = pa.array(v.tolist() if v.dtype == object else v, from_pandas=True)
        arrays.append(arr)
        fields.append(pa.field(c.name, arr.type, metadata={"unit": c.unit, "description": c.description}))
    return pa.Table.from_arrays(arrays, schema=pa.schema(fields, metadata=dict(schema_metadata)))


def _parquet(t: Table, path: Path, schema_metadata: Mapping[str, str]) -> Path:
    import pyarrow.parquet as pq

    pq.write_table(_arrow(t, schema_metadata), path)
    return path


class ColumnsChanged(RailMonitorError):
    """A part of a streamed export whose columns differ from the first part's."""


class TableSink:
    """One table written part by part (CSV appended, Parquet as row groups): the same file as
    write_tables gives for the whole table. A Parquet column that is empty in every part so far
    has no type yet: parts are held until each column has one (or the table ends)."""

    def __init__(self, name: str, fmt: str, folder: Path, schema_metadata: Mapping[str, str]) -> None:
        if fmt not in ("csv", "parquet"):
            raise RailMonitorError(f"a table written in parts is CSV or Parquet, not {fmt!r}")
        self.fmt, self.path, self.meta = fmt, folder / f"{name}.{fmt}", schema_metadata
        self.names: list[str] | None = None
        self.rows = 0
        self._held: list[Any] = []
        self._writer: Any = None

    def add(self, t: Table) -> None:
        names = [c.name for c in t.columns]
        if self.names is None:
            self.names = names
        elif names != self.names:
            raise ColumnsChanged(f"{self.path.name}: columns change along the run "
                                 f"({sorted(set(names) ^ set(self.names))[:3]})")
        first = self.rows == 0
        self.rows += len(t.columns[0].values)
        try:
            if self.fmt == "csv":
                _frame(t, excel=False).to_csv(self.path, index=False, mode="w" if first else "a", header=first)
                return
            self._held.append(_arrow(t, self.meta))
            self._write_held(final=False)
        except OSError as exc:
            raise RailMonitorError(f"{self.path}: cannot write the export: {exc.strerror or exc}") from None

    def _write_held(self, final: bool) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        if self._writer is None:
            schema = pa.unify_schemas([h.schema for h in self._held], promote_options="permissive")
            if not final and any(pa.types.is_null(f.type) for f in schema):
                return
            self._writer = pq.ParquetWriter(self.path, schema)
        for h in self._held:
            self._writer.write_table(h.cast(self._writer.schema))
        self._held = []

    def close(self) -> Path:
        if self.fmt == "parquet":
            if self._writer is None and not self._held:
                raise RailMonitorError(f"{self.path.name}: nothing to write")
            self._write_held(final=True)
            self._writer.close()
        return self.path
