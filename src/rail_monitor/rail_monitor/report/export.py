"""Tables of a recorded run (rail_monitor.report.run_tables) written for analysis elsewhere, as CSV,
Parquet or an Excel workbook, whole or part by part. Units are in the column names and, in
Parquet, in each field's metadata (``unit``, ``description``), with the site and software
version in the schema metadata.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.report.run_data import RunData
from rail_monitor.report.run_tables import Table, alert_table, pass_table

FORMATS = ("csv", "parquet", "xlsx")


# -- writing ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Written:
    """What an export wrote: (table name, rows, columns) per table, the files, and lines for the user."""

    tables: list[tuple[str, int, int]]
    files: list[Path]
    notes: list[str]


def export_run(bag: str | Path, cfg: SiteConfig, fmt: str, folder: Path,
               schema_metadata: Mapping[str, str], chunk: int = 5_000) -> Written:
    """The pass and alert tables of a recorded run written into folder (a new, empty one).

    CSV and Parquet of a bag rail_monitor recorded are written ``chunk`` passes at a time
    (memory: one part, whatever the run's length); Excel, chunk 0, or another bag are read whole.
    """
    from rail_monitor.report.run_data import NotStampOrdered, load_run

    notes: list[str] = []
    if fmt in ("csv", "parquet") and chunk > 0:
        try:
            return _export_in_parts(bag, cfg, fmt, folder, schema_metadata, chunk)
        except (NotStampOrdered, ColumnsChanged) as exc:
            for name in ("passes", "alerts"):  # the parts written so far: this export's own files
                (folder / f"{name}.{fmt}").unlink(missing_ok=True)
            notes.append(f"{exc}; read whole instead")
    run = load_run(bag)
    tables = [pass_table(run, cfg), alert_table(run, cfg)]
    files = write_tables(tables, fmt, folder, schema_metadata)
    return Written([(t.name, len(t.columns[0].values), len(t.columns)) for t in tables], files, notes)


def _export_in_parts(bag: str | Path, cfg: SiteConfig, fmt: str, folder: Path,
                     schema_metadata: Mapping[str, str], chunk: int) -> Written:
    from rail_monitor.report.run_data import iter_runs

    passes = TableSink("passes", fmt, folder, schema_metadata)
    alerts: list[Any] = []
    last: RunData | None = None
    for part in iter_runs(bag, chunk):
        passes.add(pass_table(part, cfg))
        alerts += part.alerts
        last = part
    assert last is not None  # iter_runs gives at least one part or raises
    last.alerts = sorted(alerts, key=lambda a: (a.stamp_ns, a.kind, a.key, a.active))
    table = alert_table(last, cfg)
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
