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
        if begin + length > len(data):
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
    the messages themselves (log-time order is the caller's to impose)."""
    path = Path(path)
    data = path.read_bytes()
    scan = Scan(path)
    if not data.startswith(MAGIC):
        raise InputError(f"{path}: not an MCAP file (no magic)")
    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, int]] = {}
    kept: list[ScannedMessage] = []
    channel_ids: dict[str, set[int]] = {}

    def take(records: list[Any]) -> None:
        for rec in records:
            if isinstance(rec, Schema):
                schemas[rec.id] = rec.name
            elif isinstance(rec, Channel):
                channels[rec.id] = (rec.topic, rec.schema_id)
                channel_ids.setdefault(rec.topic, set()).add(rec.id)
            elif isinstance(rec, Message) and rec.channel_id in channels:
                topic, schema_id = channels[rec.channel_id]
                scan.counts[topic] += 1
                if keep:
                    kept.append(ScannedMessage(topic, schemas.get(schema_id, ""), rec.log_time, bytes(rec.data)))

    footer_at = stats_record = None
    in_summary = False
    for opcode, content, offset in _records(data, len(MAGIC), scan):
        stream = ReadDataStream(BytesIO(content))
        try:
            if opcode == Opcode.CHUNK:
                scan.chunks += 1
                take(breakup_chunk(Chunk.read(stream), validate_crc=True))
            elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL) and in_summary:
                rec = (Schema if opcode == Opcode.SCHEMA else Channel).read(stream)
                known = schemas.get(rec.id) if opcode == Opcode.SCHEMA else channels.get(rec.id, (None,))[0]
                if known is not None and known != (rec.name if opcode == Opcode.SCHEMA else rec.topic):
                    scan.summary_mismatch += 1
            elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL):
                take([(Schema if opcode == Opcode.SCHEMA else Channel).read(stream)])
            elif opcode == Opcode.DATA_END:
                in_summary = True
            elif opcode == Opcode.MESSAGE:
                take([Message.read(stream, len(content))])
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
    if footer_at is None:
        scan.cut_off = True
    if stats_record is not None:
        scan.statistics = _per_topic(stats_record, channel_ids)
    return scan, kept


# -- cross-checks ---------------------------------------------------------------------------------
def bag_files(path: Path) -> tuple[list[Path], dict[str, Any] | None]:
    """The storage files of a bag (a folder with metadata.yaml, or one file) and its metadata.

    Refuses a metadata.yaml whose file list names a file twice or disagrees with the folder."""
    if path.is_file():
        return [path], None
    meta_path = path / "metadata.yaml"
    on_disk = sorted(p.name for p in path.iterdir() if p.suffix in (".mcap", ".db3"))
    if not meta_path.exists():
        return [path / n for n in on_disk], None
    try:
        meta = load_yaml(meta_path.read_text(encoding="utf-8"), str(meta_path))["rosbag2_bagfile_information"]
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
        stated = metadata_counts(meta)
        total = int(meta.get("message_count", sum(stated.values())))
        if total != sum(stated.values()):
            raise InputError(f"{path}: metadata.yaml counts {total} messages in all but {sum(stated.values())} "
                             "over its topics")
        if scans:
            _disagreement(path, "metadata.yaml counts", stated, "its files hold", dict(held))
    return Claims(path, dict(held) if scans else None, stated)
