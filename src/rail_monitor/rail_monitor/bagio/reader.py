"""Reading pass histories: rosbag2 bags (MCAP or sqlite3, via rosbags), bare MCAP files, CSV.

Every failure becomes an :class:`~rail_monitor.core.errors.InputError` with one line naming the
file and the cause; front ends print it without a traceback and exit non-zero.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Collection, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader

from rail_monitor.bagio.integrity import Claims, ScannedMessage, check_bag, scan_mcap
from rail_monitor.codec.typestore import (
    FRICTION_APPLICATOR,
    MEASURED_PASS_NOISE,
    ROUGHNESS_SURVEY,
    TRAIN_PASS,
    typestore,
)
from rail_monitor.core.errors import InputError, RailMonitorError
from rail_monitor.core.friction import ApplicatorEvent, applicator_refusal
from rail_monitor.core.passes import PassTable
from rail_monitor.core.user_file import regular_file
from rail_monitor.corrugation.surveys import MaintenanceEvent, in_time_order
from rail_monitor.measured.records import Measurement
from rail_monitor.messages.event_fields import applicator_from_msg, event_from_msg
from rail_monitor.messages.fields import measurement_from_msg, pass_row


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


def is_csv(path: Path) -> bool:
    return path.suffix.lower() == ".csv"


def _checked(path: Path, reader: AnyReader) -> Claims:
    """The bag's claims once it is found consistent with itself (closing the reader if it is not)."""
    try:
        return check_bag(path)
    except BaseException:
        reader.close()
        raise


def _open_bag(path: Path) -> AnyReader:
    if not path.exists():
        raise InputError(f"{path}: no such file or folder")
    if not path.is_dir() and regular_file(path, "a bag (a folder or an .mcap file)").st_size == 0:
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
    claims = _checked(path, reader)
    try:
        topics: dict[str, TopicInfo] = {}
        for c in reader.connections:
            prev = topics.get(c.topic)
            topics[c.topic] = TopicInfo(c.topic, c.msgtype, c.msgcount + (prev.count if prev else 0))
        files = [p for p in ([path] if path.is_file() else path.iterdir())]
        storage = "sqlite3" if any(p.suffix == ".db3" for p in files) else "mcap"
        info = BagInfo(path, storage, reader.start_time, reader.end_time, reader.message_count,
                       sorted(topics.values(), key=lambda t: t.name))
    except Exception as exc:
        raise InputError(f"{path}: cannot read bag: {_one_line(exc)}") from None
    finally:
        reader.close()
    claims.check_read({t.name: t.count for t in info.topics})
    if info.message_count != sum(t.count for t in info.topics):
        raise InputError(f"{path}: the bag counts {info.message_count} messages in all but "
                         f"{sum(t.count for t in info.topics)} over its topics")
    return info


def read_bag_passes(path: str | Path, topic: str | None = None) -> PassTable:
    """Every TrainPass in a bag, in log-time order. topic: the topic to read (default: the one
    TrainPass topic; more than one is an error that lists them)."""
    tables = list(iter_bag_passes(path, topic))
    return PassTable.concat(tables) if tables else PassTable.from_rows([])


def iter_bag_passes(path: str | Path, topic: str | None = None, chunk: int = 5_000) -> Iterator[PassTable]:
    """The TrainPass messages of a bag (topic as for read_bag_passes) in log-time order, as tables of
    ``chunk`` passes (the last may be shorter), so a long history is never held whole. The bag is
    checked against its own index when opened, and its message count once every pass is read."""
    path = Path(path)
    reader = _open_bag(path)
    claims = _checked(path, reader)
    n = 0
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
        rows = []
        for c, _, raw in reader.messages(connections=conns):
            rows.append(pass_row(reader.deserialize(raw, c.msgtype)))
            if len(rows) == chunk:
                n += chunk
                yield PassTable.from_rows(rows)
                rows = []
        n += len(rows)
        claims.check_read({names[0]: n})
        if rows:
            yield PassTable.from_rows(rows)
    except RailMonitorError:
        raise
    except Exception as exc:
        raise InputError(f"{path}: cannot read bag: {_one_line(exc)}") from None
    finally:
        reader.close()


def iter_messages(path: str | Path, typenames: Collection[str], chunk: int = 20_000
                  ) -> Iterator[list[tuple[str, int, Any]]]:
    """Every message of the given types in a bag (any topic), deserialised, in log-time order, as
    lists of about ``chunk`` (typename, log time [ns], message); the bag is checked against its
    own index when opened and its message counts once the last is read."""
    path = Path(path)
    reader = _open_bag(path)
    claims = _checked(path, reader)
    read: Counter[str] = Counter()
    try:
        conns = [c for c in reader.connections if c.msgtype in typenames]
        out: list[tuple[str, int, Any]] = []
        for c, t, raw in reader.messages(connections=conns) if conns else ():  # none given: rosbags reads all
            out.append((c.msgtype, t, reader.deserialize(raw, c.msgtype)))
            read[c.topic] += 1
            if len(out) >= chunk:
                yield out
                out = []
        topics = {c.topic for c in conns}
    except Exception as exc:
        raise InputError(f"{path}: cannot read bag: {_one_line(exc)}") from None
    finally:
        reader.close()
    claims.check_read({t: read[t] for t in topics})
    if out:
        yield out


def read_messages(path: str | Path, typenames: Collection[str]) -> dict[str, list[Any]]:
    """Every message of the given types in a bag (any topic), deserialised, by type, in log-time order."""
    out: dict[str, list[Any]] = {t: [] for t in typenames}
    for part in iter_messages(path, typenames):
        for typename, _, msg in part:
            out[typename].append(msg)
    return out


def read_bag_events(path: str | Path) -> list[MaintenanceEvent]:
    """The roughness surveys and grinding events (rail_msgs/RoughnessSurvey, any topic) of a bag,
    in stamp order; none for a CSV history."""
    return read_bag_inputs(path, measurements=False)[0]


def read_measurements(path: str | Path, skip_bad_rows: bool = False) -> list[Measurement]:
    """Measured pass-bys, by pass: a noise station's CSV (bagio.measured_csv; skip_bad_rows as
    there), or the MeasuredPassNoise messages (any topic) of a bag."""
    if is_csv(Path(path)):
        from rail_monitor.bagio.measured_csv import read_measured_csv

        return sorted(read_measured_csv(path, skip_bad_rows), key=lambda m: m.key)
    return read_bag_inputs(path, events=False)[1]


def read_bag_inputs(path: str | Path, events: bool = True, measurements: bool = True
                    ) -> tuple[list[MaintenanceEvent], list[Measurement]]:
    """What a history bag carries besides its passes, read together (one check of the bag, one
    read of its file): its surveys and grinding events in stamp order, and its measured pass-bys
    by pass (each only when asked for); none for a CSV history, which holds passes only."""
    if is_csv(Path(path)):
        return [], []
    msgs = read_messages(path, [t for t, wanted in ((ROUGHNESS_SURVEY, events), (MEASURED_PASS_NOISE, measurements))
                                if wanted])
    return (in_time_order([event_from_msg(m) for m in msgs.get(ROUGHNESS_SURVEY, ())]),
            sorted((measurement_from_msg(m) for m in msgs.get(MEASURED_PASS_NOISE, ())), key=lambda m: m.key))


def read_history_inputs(source: str | Path, measured: str | Path | None = None, skip_bad_rows: bool = False,
                        salvage: bool = False, surveys: Sequence[str | Path] = ()
                        ) -> tuple[list[MaintenanceEvent], list[Measurement]]:
    """The surveys and grinding events and the measured pass-bys that go with a pass history: the
    history bag's own (one read) with those of the bags ``surveys`` (e.g. rail-monitor measure
    roughness --survey-bag), in stamp order; the measurements from ``measured`` instead of the
    history's when given (a noise station's CSV or a bag; skip_bad_rows as there). A salvage
    recovers passes only, so then none of the history's own."""
    events, own = ([], []) if salvage else read_bag_inputs(source, measurements=not measured)
    for path in surveys:
        found = [] if is_csv(Path(path)) else read_bag_events(path)
        if not found:
            raise InputError(f"{path}: no {ROUGHNESS_SURVEY} in it; surveys come as a bag of them (rail-monitor "
                             "measure roughness --survey-bag writes one)")
        events += found
    return in_time_order(events), read_measurements(measured, skip_bad_rows) if measured else own


def read_applicators(path: str | Path, salvage: bool = False) -> tuple[list[ApplicatorEvent], dict[str, int]]:
    """A history bag's friction-modifier applicator starts and stops (rail_msgs/FrictionApplicator,
    any topic) in stamp order, and those refused, counted by reason; none for a CSV history or a
    salvage (which recovers passes only)."""
    if salvage or is_csv(Path(path)):
        return [], {}
    events = [applicator_from_msg(m) for m in read_messages(path, [FRICTION_APPLICATOR]).get(FRICTION_APPLICATOR, ())]
    refused = Counter(why for why in map(applicator_refusal, events) if why)
    return sorted((e for e in events if not applicator_refusal(e)), key=lambda e: e.stamp_ns), dict(refused)


def read_passes(path: str | Path, topic: str | None = None, skip_bad_rows: bool = False,
                salvage: bool = False) -> PassTable:
    """Train passes from a CSV export or a bag, whichever path names (skip_bad_rows: CSV only,
    see read_csv; salvage: MCAP only, see salvage_bag_passes; read_passes_reported says what was
    left out or salvaged)."""
    return read_passes_reported(path, topic, skip_bad_rows, salvage)[0]


@dataclass(frozen=True)
class ReadReport:
    """What reading a history left out or recovered: the CSV rows skipped ("line N: reason"), the
    salvage of a damaged bag (None when not salvaged)."""

    skipped_rows: tuple[str, ...] = ()
    salvage: SalvageReport | None = None


def read_passes_reported(path: str | Path, topic: str | None = None, skip_bad_rows: bool = False,
                         salvage: bool = False) -> tuple[PassTable, ReadReport]:
    """read_passes, with its ReadReport."""
    path = Path(path)
    if salvage:
        table, report = salvage_bag_passes(path, topic)
        return table, ReadReport(salvage=report)
    if is_csv(path):
        from rail_monitor.bagio.csv_io import read_csv_rows

        table, skipped = read_csv_rows(path, skip_bad_rows=skip_bad_rows)
        return table, ReadReport(skipped_rows=tuple(skipped))
    return read_bag_passes(path, topic), ReadReport()


def salvage_mcap(path: str | Path) -> list[ScannedMessage]:
    """Every message of the intact records of an MCAP file, in file order, even one cut off
    mid-write or with damaged chunks (skipped; bagio.integrity.scan_mcap counts them)."""
    return scan_mcap(path, keep=True)[1]


@dataclass(frozen=True)
class SalvageReport:
    files: int          # .mcap files read
    messages: int       # messages in their intact records (every topic)
    passes: int         # TrainPass messages among them (of the chosen topic)
    damaged_chunks: int = 0   # chunks skipped (failed CRC or decompression)
    cut_off: int = 0          # files whose framing ends before the footer
    unplaced: int = 0         # messages on a channel no intact record defines (lost)

    def line(self, path: str | Path) -> str:
        skipped = (f"; skipped {self.damaged_chunks} damaged chunk(s)" if self.damaged_chunks else "") + (
            f"; {self.cut_off} file(s) cut off before the footer" if self.cut_off else "") + (
            f"; {self.unplaced} message(s) lost with the only record of their channel" if self.unplaced else "")
        return (f"salvaged {self.messages} messages ({self.passes} TrainPass) from the complete chunks of "
                f"{self.files} MCAP file(s) in {path}{skipped}")


def salvage_bag_passes(path: str | Path, topic: str | None = None) -> tuple[PassTable, SalvageReport]:
    """Every TrainPass in the intact chunks of a bag's MCAP files (a folder or one .mcap file), even
    files cut off mid-write with no summary or metadata.yaml (a killed recorder, a full disk) or with
    damaged chunks between intact ones (skipped and counted; see bagio.integrity.scan_mcap).

    The passes, in log-time order (stable across split files), and a SalvageReport of what was
    recovered. topic: as in read_bag_passes.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such file or folder")
    files = sorted(path.glob("*.mcap"), key=_split_index) if path.is_dir() else [path]
    if not files:
        raise InputError(f"{path}: no .mcap files to salvage")
    rows, total, damaged, cut_off, unplaced = [], 0, 0, 0, 0
    store = typestore()
    try:
        for f in files:
            scan, messages = scan_mcap(f, keep=True)
            total += len(messages)
            damaged += scan.damaged_chunks
            cut_off += scan.cut_off
            unplaced += scan.unplaced
            for m in messages:
                if (m.topic == topic) if topic else (m.typename == TRAIN_PASS):
                    if m.typename != TRAIN_PASS:
                        raise InputError(f"{path}: topic {m.topic} is {m.typename}, not {TRAIN_PASS}")
                    rows.append((m.log_time_ns, pass_row(store.deserialize_cdr(m.data, TRAIN_PASS))))
    except RailMonitorError:
        raise
    except Exception as exc:
        raise InputError(f"{path}: cannot salvage: {_one_line(exc)}") from None
    rows.sort(key=lambda r: r[0])
    report = SalvageReport(len(files), total, len(rows), damaged, cut_off, unplaced)
    return PassTable.from_rows([r for _, r in rows]), report


def _split_index(path: Path) -> tuple[int, str]:
    """rosbag2 names split files <bag>_<k>.mcap: order them by k."""
    stem = path.stem.rsplit("_", 1)
    return (int(stem[1]), path.name) if len(stem) == 2 and stem[1].isdigit() else (-1, path.name)
