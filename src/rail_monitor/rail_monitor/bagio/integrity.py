"""What a bag holds, read independently of its index, and the cross-checks against what it claims.

An MCAP file is read here record by record in file order (opcode, length, content): a chunk whose
content does not decompress or fails its CRC is counted and skipped, and the scan goes on at the
next record, since the record's length says where that is. Only a record whose framing is cut off
(a killed writer's tail) ends the scan. The counts per topic of what the intact chunks hold are
then compared with what the indexed reader returned, with the file's Statistics record and with
``metadata.yaml`` (its file list and its counts): a bag that disagrees with itself is refused with
one line naming the file and both numbers, unless the user asks to salvage it.
"""

from __future__ import annotations

import mmap
import struct
import zlib
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from io import BytesIO
from pathlib import Path
from typing import Any

from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, Footer, Message, Schema, Statistics
from mcap.stream_reader import breakup_chunk

from rail_monitor.bagio.mcap_bag import OPEN_FILE_KEY
from rail_monitor.core.errors import InputError
from rail_monitor.core.timeutil import TIME_MSG_END_NS
from rail_monitor.core.user_file import read_user_text, regular_file
from rail_monitor.core.yaml_text import load_yaml

MAGIC = b"\x89MCAP0\r\n"
_FRAME = struct.Struct("<BQ")  # opcode, content length


@dataclass
class ScannedMessage:
    topic: str
    typename: str
    log_time_ns: int
    data: bytes


@dataclass
class Scan:
    """What one MCAP file holds, read in file order."""

    path: Path
    counts: Counter[str] = field(default_factory=Counter)     # messages per topic in intact records
    chunks: int = 0
    damaged_chunks: int = 0
    cut_off: bool = False                                      # the framing ends before the footer
    statistics: dict[str, int] | None = None                   # the Statistics record's count per topic
    summary_crc_ok: bool | None = None                         # None: no summary CRC to check
    summary_mismatch: int = 0                                  # summary schemas/channels unlike the data's
    unplaced: int = 0                                          # messages on a channel no intact record defines
    types: dict[str, str] = field(default_factory=dict)        # each topic's schema name

    def problems(self) -> list[str]:
        """Why the file disagrees with itself, one phrase each (empty: it does not)."""
        out = []
        if self.damaged_chunks:
            out.append(f"{self.damaged_chunks} of {self.chunks} chunks damaged")
        if self.cut_off:
            out.append("cut off before its footer")
        if self.summary_crc_ok is False:
            out.append("its summary fails its CRC")
        if self.summary_mismatch:
            out.append(f"{self.summary_mismatch} schema or channel record(s) of its summary differ from its data")
        if self.unplaced:
            out.append(f"{self.unplaced} message(s) on channels no intact record defines")
        if self.statistics is not None and dict(self.statistics) != {t: n for t, n in self.counts.items() if n}:
            for topic in sorted(set(self.statistics) | set(self.counts)):
                want, got = self.statistics.get(topic, 0), self.counts.get(topic, 0)
                if want != got:
                    out.append(f"its statistics count {want} messages on {topic}, its chunks hold {got}")
        return out


def _records(data: bytes, start: int, scan: Scan) -> Iterator[tuple[int, bytes, int]]:
    """(opcode, content, offset) of each record from start; marks scan.cut_off at a broken frame."""
    pos = start
    while pos + _FRAME.size <= len(data):
        opcode, length = _FRAME.unpack_from(data, pos)
        begin = pos + _FRAME.size
        if opcode == 0 or begin + length > len(data):  # opcode 0 is invalid: a zero-filled tail
            scan.cut_off = True
            return
        yield opcode, data[begin:begin + length], pos
        if opcode == Opcode.FOOTER:
            return
        pos = begin + length
    scan.cut_off = True


def _per_topic(stats: Statistics, channel_ids: dict[str, set[int]]) -> dict[str, int]:
    """A Statistics record's message counts per topic (and its total, where that disagrees)."""
    by_channel = stats.channel_message_counts
    out = {topic: sum(by_channel.get(i, 0) for i in ids) for topic, ids in channel_ids.items()}
    if sum(by_channel.values()) != stats.message_count:  # the record disagrees with itself
        out["(all topics)"] = stats.message_count
    return {t: n for t, n in out.items() if n}


def scan_mcap(path: str | Path, keep: bool = False) -> tuple[Scan, list[ScannedMessage]]:
    """Read an MCAP file in file order: the counts of what its intact records hold and, with keep,
    the messages themselves (log-time order is the caller's to impose).

    Schemas and channels are learned from every intact copy, the data's and the summary's, before
    any message is placed: a damaged chunk that held the only data copy of a channel loses its own
    messages, not the later chunks' (issue 52). A message on a channel no intact record defines is
    counted in ``unplaced``."""
    path = Path(path)
    size = regular_file(path, "an MCAP file").st_size
    try:
        with open(path, "rb") as fh:
            # Mapped, not read: a file of gigabytes (or a sparse one) is paged in as it is scanned.
            data = mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) if size else b""
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read the MCAP file: {exc}") from None
    try:
        return _scan(path, data, keep)
    finally:
        if isinstance(data, mmap.mmap):
            data.close()


def _scan(path: Path, data: bytes | mmap.mmap, keep: bool) -> tuple[Scan, list[ScannedMessage]]:
    scan = Scan(path)
    if data[:len(MAGIC)] != MAGIC:
        raise InputError(f"{path}: not an MCAP file (no magic)")
    body: list[Any] = []       # the data section's intact records, in file order (chunks opened)
    summary: list[Any] = []    # the summary's schema and channel records
    footer_at = stats_record = None
    in_summary = False
    for opcode, content, offset in _records(data, len(MAGIC), scan):
        stream = ReadDataStream(BytesIO(content))
        try:
            if opcode == Opcode.CHUNK:
                scan.chunks += 1
                body += breakup_chunk(Chunk.read(stream), validate_crc=True)
            elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL):
                rec = (Schema if opcode == Opcode.SCHEMA else Channel).read(stream)
                (summary if in_summary else body).append(rec)
            elif opcode == Opcode.DATA_END:
                in_summary = True
            elif opcode == Opcode.MESSAGE:
                body.append(Message.read(stream, len(content)))
            elif opcode == Opcode.STATISTICS:
                stats_record = Statistics.read(stream)
            elif opcode == Opcode.FOOTER:
                footer_at = offset
                footer = Footer.read(stream)
                if footer.summary_crc and footer.summary_start:
                    # The CRC covers the summary from its start through the footer's summary_crc field.
                    end = offset + _FRAME.size + 16
                    scan.summary_crc_ok = zlib.crc32(data[footer.summary_start:end]) == footer.summary_crc
        except Exception:  # a damaged record: mcap raises many types; the framing around it is intact
            if opcode == Opcode.CHUNK:
                scan.damaged_chunks += 1
    schemas: dict[int, str] = {r.id: r.name for r in body if isinstance(r, Schema)}
    channels: dict[int, tuple[str, int]] = {r.id: (r.topic, r.schema_id) for r in body if isinstance(r, Channel)}
    for rec in summary:  # the summary's copies: checked against the data's, and used where the data has none
        known = schemas.get(rec.id) if isinstance(rec, Schema) else channels.get(rec.id, (None,))[0]
        if known is None:
            if isinstance(rec, Schema):
                schemas[rec.id] = rec.name
            else:
                channels[rec.id] = (rec.topic, rec.schema_id)
        elif known != (rec.name if isinstance(rec, Schema) else rec.topic):
            scan.summary_mismatch += 1
    channel_ids: dict[str, set[int]] = {}
    for cid, (topic, _) in channels.items():
        channel_ids.setdefault(topic, set()).add(cid)
    kept: list[ScannedMessage] = []
    for rec in body:
        if not isinstance(rec, Message):
            continue
        if rec.channel_id not in channels:
            scan.unplaced += 1
            continue
        topic, schema_id = channels[rec.channel_id]
        scan.counts[topic] += 1
        if keep:
            kept.append(ScannedMessage(topic, schemas.get(schema_id, ""), rec.log_time, bytes(rec.data)))
    scan.types = {topic: schemas.get(schema_id, "") for topic, schema_id in channels.values()}
    if footer_at is None:
        scan.cut_off = True
    if stats_record is not None:
        scan.statistics = _per_topic(stats_record, channel_ids)
    return scan, kept


# -- cross-checks ---------------------------------------------------------------------------------
def bag_files(path: Path) -> tuple[list[Path], dict[str, Any] | None]:
    """The storage files of a bag (a folder with metadata.yaml, or one file) and its metadata.

    Refuses a metadata.yaml whose file list names a file twice or disagrees with the folder."""
    if not path.is_dir():
        regular_file(path, "a bag (a folder or an .mcap file)")
        return [path], None
    meta_path = path / "metadata.yaml"
    on_disk = sorted(p.name for p in path.iterdir() if p.suffix in (".mcap", ".db3"))
    if not meta_path.exists():
        return [path / n for n in on_disk], None
    try:
        text = read_user_text(meta_path, "a rosbag2 metadata file")
        meta = load_yaml(text, str(meta_path))["rosbag2_bagfile_information"]
        listed = [str(p) for p in meta.get("relative_file_paths") or []]
    except InputError:
        raise
    except Exception as exc:
        raise InputError(f"{meta_path}: not a rosbag2 metadata file: {type(exc).__name__}") from None
    if len(set(listed)) < len(listed):
        raise InputError(f"{meta_path}: lists a file more than once ({', '.join(listed)})")
    custom = meta.get("custom_data")
    open_file = custom.get(OPEN_FILE_KEY) if isinstance(custom, dict) else None
    if open_file and sorted([*listed, open_file]) == on_disk:
        raise InputError(f"{path / open_file}: was being written when the recording stopped (a kill or a power "
                         f"cut); metadata.yaml lists the {len(listed)} finished file(s); --salvage reads them and "
                         "its complete chunks")
    if sorted(listed) != on_disk:
        raise InputError(f"{meta_path}: lists {len(listed)} file(s) ({', '.join(listed) or 'none'}) but the folder "
                         f"holds {len(on_disk)} ({', '.join(on_disk) or 'none'})")
    return [path / n for n in listed], meta


def _check_times(path: Path, meta: dict[str, Any]) -> None:
    """metadata.yaml's start and duration must be times a stamp can hold (InputError otherwise)."""
    try:
        start = int(meta["starting_time"]["nanoseconds_since_epoch"])
        duration = int(meta["duration"]["nanoseconds"])
    except (KeyError, TypeError, ValueError, OverflowError):
        raise InputError(f"{path}: metadata.yaml has no readable starting_time and duration; --salvage reads "
                         "the MCAP files alone") from None
    if not (0 <= start < TIME_MSG_END_NS and duration >= 0 and start + duration < TIME_MSG_END_NS):
        raise InputError(f"{path}: metadata.yaml's starting_time {start} ns and duration {duration} ns are not "
                         "times a stamp can hold; --salvage reads the MCAP files alone")


def _check_types(path: Path, meta: dict[str, Any], scans: list[Scan]) -> None:
    """metadata.yaml's type of each topic must be the type its files' channels are written with."""
    held = {topic: name for s in scans for topic, name in s.types.items()}
    for entry in meta.get("topics_with_message_count") or []:
        tm = entry["topic_metadata"]
        if tm["name"] in held and str(tm.get("type")) != held[tm["name"]]:
            raise InputError(f"{path}: metadata.yaml says topic {tm['name']} is {tm.get('type')}, its files hold "
                             f"{held[tm['name']]}; --salvage reads the MCAP files alone")


def metadata_counts(meta: dict[str, Any]) -> dict[str, int]:
    """Messages per topic as metadata.yaml states them."""
    out: dict[str, int] = {}
    for entry in meta.get("topics_with_message_count") or []:
        name = entry["topic_metadata"]["name"]
        out[name] = out.get(name, 0) + int(entry["message_count"])
    return out


def _disagreement(path: Path, a_name: str, a: dict[str, int], b_name: str, b: dict[str, int],
                  topics: set[str] | None = None) -> None:
    for topic in sorted(topics if topics is not None else set(a) | set(b)):
        if a.get(topic, 0) != b.get(topic, 0):
            raise InputError(f"{path}: {a_name} {a.get(topic, 0)} messages on {topic} but {b_name} "
                             f"{b.get(topic, 0)}; --salvage reads what is intact")


@dataclass(frozen=True)
class Claims:
    """What a bag says it holds, once checked against itself: messages per topic in its files
    (None for sqlite3 storage) and in its metadata.yaml (None without one)."""

    path: Path
    held: dict[str, int] | None
    stated: dict[str, int] | None

    def check_read(self, read: dict[str, int]) -> None:
        """Refuse (InputError) when the messages per topic read from the bag differ from what it holds."""
        if self.held is not None:
            _disagreement(self.path, "read", read, "its files hold", self.held, set(read))
        elif self.stated is not None:
            _disagreement(self.path, "read", read, "metadata.yaml counts", self.stated, set(read))


def check_bag(path: str | Path) -> Claims:
    """Refuse (InputError, one line) a bag that disagrees with itself: a damaged or cut-off MCAP
    file, a summary unlike its data, a metadata.yaml whose files or counts are not the folder's.
    Returns what it holds, for :meth:`Claims.check_read` after a read."""
    path = Path(path)
    files, meta = bag_files(path)
    scans = [scan_mcap(f)[0] for f in files if f.suffix == ".mcap"]
    for s in scans:
        problems = s.problems()
        if problems:
            raise InputError(f"{s.path}: the file disagrees with itself ({'; '.join(problems)}); "
                             "--salvage reads what is intact")
    held: Counter[str] = Counter()
    for s in scans:
        held.update(s.counts)
    stated = None
    if meta is not None:
        _check_times(path, meta)
        stated = metadata_counts(meta)
        if scans:
            _check_types(path, meta, scans)
        total = int(meta.get("message_count", sum(stated.values())))
        if total != sum(stated.values()):
            raise InputError(f"{path}: metadata.yaml counts {total} messages in all but {sum(stated.values())} "
                             "over its topics")
        if scans:
            _disagreement(path, "metadata.yaml counts", stated, "its files hold", dict(held))
    return Claims(path, dict(held) if scans else None, stated)
