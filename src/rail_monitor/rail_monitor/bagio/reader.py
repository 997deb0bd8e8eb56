"""Reading pass histories: rosbag2 bags (MCAP or sqlite3, via rosbags), bare MCAP files, CSV.

Every failure becomes an :class:`~rail_monitor.core.errors.InputError` with one line naming the
file and the cause; front ends print it without a traceback and exit non-zero.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader
from rosbags.highlevel import AnyReader

from rail_monitor.bagio.messages import pass_row
from rail_monitor.bagio.typestore import TRAIN_PASS, typestore
from rail_monitor.core.errors import InputError, RailMonitorError
from rail_monitor.core.passes import PassTable


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


def is_csv(path: Path) -> bool:
    return path.suffix.lower() == ".csv"


def _open_bag(path: Path) -> AnyReader:
    if not path.exists():
        raise InputError(f"{path}: no such file or folder")
    if path.is_file() and path.stat().st_size == 0:
        raise InputError(f"{path}: empty file, not a bag")
    try:
        reader = AnyReader([path], default_typestore=typestore())
        reader.open()
    except RailMonitorError:
        raise
    except Exception as exc:  # rosbags raises many types for corrupt input; all mean "unusable"
        raise InputError(f"{path}: cannot open bag: {_one_line(exc)}") from None
    return reader


@dataclass(frozen=True)
class TopicInfo:
    name: str
    typename: str
    count: int


@dataclass(frozen=True)
class BagInfo:
    path: Path
    storage: str
    start_ns: int
    end_ns: int
    message_count: int
    topics: list[TopicInfo]


def bag_info(path: str | Path) -> BagInfo:
    """Storage, time span and per-topic counts of a bag (folder, .mcap or .db3)."""
    path = Path(path)
    reader = _open_bag(path)
    try:
        topics: dict[str, TopicInfo] = {}
        for c in reader.connections:
            prev = topics.get(c.topic)
            topics[c.topic] = TopicInfo(c.topic, c.msgtype, c.msgcount + (prev.count if prev else 0))
        files = [p for p in ([path] if path.is_file() else path.iterdir())]
        storage = "sqlite3" if any(p.suffix == ".db3" for p in files) else "mcap"
        return BagInfo(path, storage, reader.start_time, reader.end_time, reader.message_count,
                       sorted(topics.values(), key=lambda t: t.name))
    except Exception as exc:
        raise InputError(f"{path}: cannot read bag: {_one_line(exc)}") from None
    finally:
        reader.close()


def read_bag_passes(path: str | Path, topic: str | None = None) -> PassTable:
    """Every TrainPass in a bag, in log-time order. topic: the topic to read (default: the one
    TrainPass topic; more than one is an error that lists them)."""
    path = Path(path)
    reader = _open_bag(path)
    try:
        conns = [c for c in reader.connections if (c.topic == topic if topic else c.msgtype == TRAIN_PASS)]
        if not conns:
            have = sorted({f"{c.topic} [{c.msgtype}]" for c in reader.connections}) or ["no topics"]
            want = f"topic {topic}" if topic else f"{TRAIN_PASS} topic"
            raise InputError(f"{path}: no {want} in the bag; it has {', '.join(have)}")
        bad = [c for c in conns if c.msgtype != TRAIN_PASS]
        if bad:
            raise InputError(f"{path}: topic {bad[0].topic} is {bad[0].msgtype}, not {TRAIN_PASS}")
        names = sorted({c.topic for c in conns})
        if len(names) > 1:
            raise InputError(f"{path}: several TrainPass topics ({', '.join(names)}); choose one with --topic")
        rows = [pass_row(reader.deserialize(raw, c.msgtype)) for c, _, raw in reader.messages(connections=conns)]
    except RailMonitorError:
        raise
    except Exception as exc:
        raise InputError(f"{path}: cannot read bag: {_one_line(exc)}") from None
    finally:
        reader.close()
    return PassTable.from_rows(rows)


def read_messages(path: str | Path, typenames: Collection[str]) -> dict[str, list[Any]]:
    """Every message of the given types in a bag (any topic), deserialised, by type, in log-time order."""
    path = Path(path)
    reader = _open_bag(path)
    out: dict[str, list[Any]] = {t: [] for t in typenames}
    try:
        conns = [c for c in reader.connections if c.msgtype in out]
        for c, _, raw in reader.messages(connections=conns):
            out[c.msgtype].append(reader.deserialize(raw, c.msgtype))
    except Exception as exc:
        raise InputError(f"{path}: cannot read bag: {_one_line(exc)}") from None
    finally:
        reader.close()
    return out


def read_passes(path: str | Path, topic: str | None = None, skip_bad_rows: bool = False,
                salvage: bool = False) -> PassTable:
    """Train passes from a CSV export or a bag, whichever path names (skip_bad_rows: CSV only,
    see read_csv; the table's ``skipped`` attribute counts what was left out; salvage: MCAP only,
    see salvage_bag_passes)."""
    path = Path(path)
    if salvage:
        return salvage_bag_passes(path, topic)
    if is_csv(path):
        from rail_monitor.bagio.csv_io import read_csv

        return read_csv(path, skip_bad_rows=skip_bad_rows)
    return read_bag_passes(path, topic)


@dataclass(frozen=True)
class SalvagedMessage:
    topic: str
    typename: str
    log_time_ns: int
    data: bytes


def salvage_mcap(path: str | Path) -> Iterator[SalvagedMessage]:
    """Every message of every complete chunk of an MCAP file, even one cut off mid-write.

    Reads records in file order with mcap's StreamReader (no summary section needed; chunk
    CRCs checked) and stops quietly at the first incomplete or corrupt record (the end of a
    killed writer's output). mcap's NonSeekingReader gives up on such a file altogether.
    """
    path = Path(path)
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    with open(path, "rb") as stream:
        records = iter(StreamReader(stream, validate_crcs=True).records)
        while True:
            try:
                rec = next(records)
            except StopIteration:
                return
            except Exception:  # truncated or corrupt tail: everything before it was yielded
                return
            if isinstance(rec, Schema):
                schemas[rec.id] = rec
            elif isinstance(rec, Channel):
                channels[rec.id] = rec
            elif isinstance(rec, Message) and rec.channel_id in channels:
                ch = channels[rec.channel_id]
                schema = schemas.get(ch.schema_id)
                yield SalvagedMessage(ch.topic, schema.name if schema else "", rec.log_time, rec.data)


@dataclass(frozen=True)
class SalvageReport:
    files: int          # .mcap files read
    messages: int       # messages in their complete chunks (every topic)
    passes: int         # TrainPass messages among them (of the chosen topic)

    def line(self, path: str | Path) -> str:
        return (f"salvaged {self.messages} messages ({self.passes} TrainPass) from the complete chunks of "
                f"{self.files} MCAP file(s) in {path}")


def salvage_bag_passes(path: str | Path, topic: str | None = None) -> PassTable:
    """Every TrainPass in the complete chunks of a bag's MCAP files (a folder or one .mcap file),
    even files cut off mid-write with no summary or metadata.yaml (a killed recorder, a full disk).

    The table's ``salvage`` attribute (SalvageReport) says what was recovered. Passes are in
    log-time order (stable across split files). topic: as in read_bag_passes.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such file or folder")
    files = sorted(path.glob("*.mcap"), key=_split_index) if path.is_dir() else [path]
    if not files:
        raise InputError(f"{path}: no .mcap files to salvage")
    rows, total = [], 0
    store = typestore()
    try:
        for f in files:
            for m in salvage_mcap(f):
                total += 1
                if (m.topic == topic) if topic else (m.typename == TRAIN_PASS):
                    if m.typename != TRAIN_PASS:
                        raise InputError(f"{path}: topic {m.topic} is {m.typename}, not {TRAIN_PASS}")
                    rows.append((m.log_time_ns, pass_row(store.deserialize_cdr(m.data, TRAIN_PASS))))
    except RailMonitorError:
        raise
    except Exception as exc:
        raise InputError(f"{path}: cannot salvage: {_one_line(exc)}") from None
    rows.sort(key=lambda r: r[0])
    table = PassTable.from_rows([r for _, r in rows])
    table.salvage = SalvageReport(len(files), total, len(rows))  # type: ignore[attr-defined]
    return table


def _split_index(path: Path) -> tuple[int, str]:
    """rosbag2 names split files <bag>_<k>.mcap: order them by k."""
    stem = path.stem.rsplit("_", 1)
    return (int(stem[1]), path.name) if len(stem) == 2 and stem[1].isdigit() else (-1, path.name)
