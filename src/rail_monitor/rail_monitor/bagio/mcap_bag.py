"""A rosbag2-compatible MCAP bag writer: one folder, metadata.yaml version 9, split files.

Layout and fields follow rosbag2 Jazzy's MCAP storage: header profile ``ros2``; one schema per type
with encoding ``ros2msg`` (full dependency text); channels with message encoding ``cdr`` and metadata
``offered_qos_profiles`` (YAML text) and ``topic_type_hash`` (RIHS01); a ``rosbag2`` metadata record;
zstd-compressed chunks. Chunks are closed at least every ``flush_period_ns`` of log time or wall
time, and every write goes to the OS at once, so a killed process leaves every complete chunk
readable (see :func:`rail_monitor.bagio.integrity.scan_mcap`).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import time
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from mcap.writer import CompressionType, Writer

from rail_monitor.bagio.direct_file import DirectFile
from rail_monitor.bagio.output_folder import Claim, new_output_folder
from rail_monitor.bagio.retention import Retention
from rail_monitor.codec.typestore import schema_text, type_hash
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.timeutil import format_iso_ns
from rail_monitor.messages.topics import qos_dict

# metadata.yaml custom_data key naming the file being written when the metadata was last written
# (a recording that splits rewrites metadata.yaml at every split: a power cut leaves the finished
# files listed, and this one for --salvage).
OPEN_FILE_KEY = "rail_monitor.open_file"


def _dump(obj: Any) -> str:
    return yaml.safe_dump(obj, sort_keys=False, default_flow_style=False)


@dataclass
class _Topic:
    name: str
    typename: str
    qos: list[dict[str, Any]]
    count: int = 0


@dataclass
class _File:
    path: Path
    writer: Writer
    stream: Any
    channel_ids: dict[str, int] = field(default_factory=dict)
    first_ns: int | None = None
    last_ns: int = 0
    count: int = 0
    topic_counts: Counter[str] = field(default_factory=Counter)
    size: int = 0  # bytes on disk once finished


class McapBagWriter:
    """Write CDR-serialised messages into a rosbag2 MCAP bag folder.

    Parameters: folder [path] (must not exist, or be empty); compression 'zstd' or 'none';
    chunk_size [bytes] of uncompressed messages per chunk; max_file_bytes [bytes] and
    max_file_duration_ns [ns] of log time to start a new file (0: no split); flush_period_ns
    [ns] of log time after which an open chunk is closed (0: only when full);
    flush_wall_period_s [s] of wall time likewise (0: never).

    Retention, for a recorder that runs for months: max_total_bytes [bytes] keeps the folder's
    files within that budget and max_age_ns [ns] deletes files whose last message is older than
    that before the newest one (0: no limit). Only finished split files this writer created are
    deleted, oldest first, never the open one. At every split the finished file is synced and
    metadata.yaml rewritten (atomically) to list the files kept.

    records: MCAP metadata records (name -> string map) written at the start of every file;
    custom_data: string entries for metadata.yaml's custom_data (bagio.site_record makes both).
    """

    def __init__(self, folder: str | Path, *, compression: str = "zstd", chunk_size: int = 1 << 20,
                 max_file_bytes: int = 0, max_file_duration_ns: int = 0, flush_period_ns: int = 0,
                 flush_wall_period_s: float = 0.0, max_total_bytes: int = 0, max_age_ns: int = 0,
                 records: dict[str, dict[str, str]] | None = None, custom_data: dict[str, str] | None = None,
                 claim: Claim | None = None) -> None:
        if compression not in ("zstd", "none"):
            raise RailMonitorError(f"compression must be 'zstd' or 'none', not {compression!r}")
        self._retention = Retention.checked(max_total_bytes, max_age_ns, max_file_bytes, max_file_duration_ns,
                                            chunk_size)
        self.folder = new_output_folder(Path(folder), claim)
        self._compression = CompressionType.ZSTD if compression == "zstd" else CompressionType.NONE
        self._chunk_size = chunk_size
        self._max_bytes, self._max_duration = max_file_bytes, max_file_duration_ns
        self._flush_ns, self._flush_wall = flush_period_ns, flush_wall_period_s
        self._last_flush_ns = 0
        self._last_flush_wall = time.monotonic()
        self._records = dict(records or {})
        self._custom = dict(custom_data or {})
        self._topics: dict[str, _Topic] = {}
        self._files: list[_File] = []  # the files kept, oldest first (the open one last)
        self._file: _File | None = None
        self._next_index = 0
        self._newest_ns = 0
        self.deleted: list[str] = []  # split files removed by retention, oldest first
        self.deleted_bytes = 0
        self.closed = False
        self.error = ""  # the first write error (e.g. a full disk); the bag takes no more messages

    # -- topics and files -------------------------------------------------------------------
    def add_topic(self, topic: str, typename: str, offered_qos: list[dict[str, Any]] | None = None) -> None:
        """Declare a topic before writing to it (idempotent for the same type)."""
        known = self._topics.get(topic)
        if known is not None:
            if known.typename != typename:
                raise RailMonitorError(f"topic {topic} already recorded as {known.typename}, not {typename}")
            return
        self._topics[topic] = _Topic(topic, typename, offered_qos if offered_qos is not None else [qos_dict()])
        if self._file is not None:
            self._register(self._file, self._topics[topic])

    def _register(self, f: _File, t: _Topic) -> None:
        schema_id = f.writer.register_schema(name=t.typename, encoding="ros2msg",
                                             data=schema_text(t.typename).encode())
        f.channel_ids[t.name] = f.writer.register_channel(
            topic=t.name, message_encoding="cdr", schema_id=schema_id,
            metadata={"offered_qos_profiles": _dump(t.qos).rstrip("\n"), "topic_type_hash": type_hash(t.typename)},
        )

    def _file_path(self, index: int) -> Path:
        return self.folder / f"{self.folder.name}_{index}.mcap"

    def _open_file(self) -> _File:
        path = self._file_path(self._next_index)
        self._next_index += 1
        stream = DirectFile(path)
        writer = Writer(stream, chunk_size=self._chunk_size, compression=self._compression)
        writer.start(profile="ros2", library="rail_monitor")
        for name, record in self._records.items():
            writer.add_metadata(name, record)
        f = _File(path, writer, stream)
        for t in self._topics.values():
            self._register(f, t)
        self._files.append(f)
        return f

    def _close_file(self, f: _File) -> None:
        f.writer.add_metadata("rosbag2", {"serialized_metadata": _dump(self._info()), "ROS_DISTRO": "jazzy"})
        f.writer.finish()
        f.size = f.stream.tell()
        os.fsync(f.stream.fileno())
        f.stream.close()

    def _split(self, f: _File) -> None:
        """Finish the open file, apply retention, and list the files kept in metadata.yaml (with
        the next file named as open)."""
        self._close_file(f)
        self._file = None
        self._retain(next_file=True)  # the next file opens with the next message
        self._write_metadata(open_file=self._file_path(self._next_index).name)

    def _retain(self, next_file: bool) -> None:
        """Delete the oldest finished files the retention settings no longer keep (next_file: a
        file is still to come, so its allowance is held back)."""
        finished = [f for f in self._files if f is not self._file]
        n = self._retention.oldest_to_delete([f.size for f in finished], [f.last_ns for f in finished],
                                             self._newest_ns, file_open=next_file)
        for old in finished[:n]:
            old.path.unlink()
            self._files.remove(old)
            self.deleted.append(old.path.name)
            self.deleted_bytes += old.size

    # -- writing ----------------------------------------------------------------------------
    def write(self, topic: str, data: bytes, log_time_ns: int) -> None:
        """Append one serialised message [CDR bytes] at log_time_ns [ns since the epoch], its publish time."""
        self.write_many(topic, [data], [log_time_ns])

    def written(self, topic: str) -> int:
        """Messages of the topic written so far (0: none, or not added)."""
        return self._topics[topic].count if topic in self._topics else 0

    def write_many(self, topic: str, datas: Sequence[bytes], log_times_ns: Sequence[int]) -> None:
        """Append messages of one topic in order, as write one by one (the flush period looked at after the last)."""
        if self.closed or self.error:
            raise RailMonitorError("bag writer is closed" if self.closed else self.error)
        t = self._topics.get(topic)
        if t is None:
            raise RailMonitorError(f"topic {topic} was not added to the bag")
        with self._failing_on_os_error():
            for data, log_time_ns in zip(datas, log_times_ns, strict=True):
                f = self._file
                if f is not None and f.first_ns is not None and (
                    (self._max_bytes and f.stream.tell() >= self._max_bytes)
                    or (self._max_duration and log_time_ns - f.first_ns >= self._max_duration)
                ):
                    self._split(f)
                    f = None
                if f is None:
                    f = self._file = self._open_file()
                f.writer.add_message(channel_id=f.channel_ids[topic], log_time=log_time_ns, data=data,
                                     publish_time=log_time_ns, sequence=t.count)
                f.first_ns = log_time_ns if f.first_ns is None else min(f.first_ns, log_time_ns)
                f.last_ns = max(f.last_ns, log_time_ns)
                self._newest_ns = max(self._newest_ns, log_time_ns)
                f.count, t.count = f.count + 1, t.count + 1
                f.topic_counts[topic] += 1
        if len(datas):
            self._maybe_flush(log_times_ns[-1])

    def _maybe_flush(self, log_time_ns: int) -> None:
        now = time.monotonic()
        by_log = self._flush_ns and log_time_ns - self._last_flush_ns >= self._flush_ns
        by_wall = self._flush_wall and now - self._last_flush_wall >= self._flush_wall
        if by_log or by_wall:
            with self._failing_on_os_error():
                self.flush()
            self._last_flush_ns, self._last_flush_wall = log_time_ns, now

    def flush(self) -> None:
        """Close the open chunk and hand it to the OS (messages so far survive a kill)."""
        if self._file is not None and not self.error:
            with self._failing_on_os_error():
                self._file.writer.flush()

    @contextlib.contextmanager
    def _failing_on_os_error(self) -> Iterator[None]:
        """Turn an OSError into RailMonitorError and stop the bag: after a failed write the open
        chunk is lost and the file ends at the last whole record, which salvage_mcap reads."""
        try:
            yield
        except OSError as exc:
            where = self._file.path if self._file is not None else self.folder
            self.error = f"{where}: write failed, recording stopped: {exc.strerror or exc}"
            raise RailMonitorError(self.error) from None

    def sync(self) -> None:
        """flush, then fsync the open file (survives a power loss)."""
        if self._file is not None:
            self.flush()
            os.fsync(self._file.stream.fileno())

    # -- metadata ---------------------------------------------------------------------------
    @property
    def message_count(self) -> int:
        """Messages written (those in files deleted by retention included)."""
        return sum(t.count for t in self._topics.values())

    def topic_counts(self) -> dict[str, int]:
        """Messages written per topic (those in deleted files included)."""
        return {t.name: t.count for t in self._topics.values()}

    def health(self) -> dict[str, Any]:
        """For /diagnostics: bytes written, kept and deleted, files kept and the oldest, free disk."""
        open_bytes = self._file.stream.tell() if self._file is not None and not self.closed else 0
        kept = sum(f.size for f in self._files if f is not self._file) + open_bytes
        try:
            free = shutil.disk_usage(self.folder).free
        except OSError:
            free = -1
        oldest = self._files[0] if self._files else None
        return {"bytes written": kept + self.deleted_bytes, "bytes kept": kept, "files kept": len(self._files),
                "oldest kept file": oldest.path.name if oldest else "",
                "oldest kept message": format_iso_ns(oldest.first_ns) if oldest and oldest.first_ns else "",
                "files deleted (retention)": len(self.deleted), "free disk bytes": free}

    def _write_metadata(self, open_file: str | None = None) -> None:
        """metadata.yaml for the finished files kept, replaced atomically and synced."""
        info = self._info([f for f in self._files if f is not self._file])
        if open_file is not None:
            info["custom_data"] = {**(info["custom_data"] or {}), OPEN_FILE_KEY: open_file}
        tmp = self.folder / "metadata.yaml.tmp"
        with open(tmp, "w", encoding="utf-8") as out:
            out.write(_dump({"rosbag2_bagfile_information": info}))
            out.flush()
            os.fsync(out.fileno())
        os.replace(tmp, self.folder / "metadata.yaml")
        fd = os.open(self.folder, os.O_RDONLY)
        try:
            os.fsync(fd)  # the rename itself survives a power loss
        finally:
            os.close(fd)

    def _info(self, files: list[_File] | None = None) -> dict[str, Any]:
        """rosbag2 metadata of files (default: every file kept), counts from those files."""
        files = self._files if files is None else files
        counts: Counter[str] = Counter()
        for f in files:
            counts.update(f.topic_counts)
        start = min((f.first_ns for f in files if f.first_ns is not None), default=0)
        end = max((f.last_ns for f in files), default=0)
        return {
            "version": 9,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": max(0, end - start)},
            "starting_time": {"nanoseconds_since_epoch": start},
            "message_count": sum(counts.values()),
            "topics_with_message_count": [
                {
                    "topic_metadata": {
                        "name": t.name, "type": t.typename, "serialization_format": "cdr",
                        "offered_qos_profiles": t.qos, "type_description_hash": type_hash(t.typename),
                    },
                    "message_count": counts[t.name],
                }
                for t in self._topics.values()
            ],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [f.path.name for f in files],
            "files": [
                {"path": f.path.name, "starting_time": {"nanoseconds_since_epoch": f.first_ns or 0},
                 "duration": {"nanoseconds": f.last_ns - (f.first_ns or f.last_ns)}, "message_count": f.count}
                for f in files
            ],
            "custom_data": dict(self._custom) or None,
            "ros_distro": "jazzy",
        }

    def close(self) -> Path:
        """Finish the open file and write metadata.yaml; returns the bag folder.

        After a write error (self.error) the file cannot be finished: RailMonitorError, and the
        file keeps the whole records written before the error (salvage_mcap reads them)."""
        if self.closed:
            return self.folder
        try:
            if self.error:
                raise RailMonitorError(self.error)
            with self._failing_on_os_error():
                if self._file is None:  # an empty bag still gets one valid file
                    self._file = self._open_file()
                self._close_file(self._file)
                self._file = None
                self._retain(next_file=False)
                self._write_metadata()
        finally:
            self.closed = True
            if self._file is not None:
                with contextlib.suppress(OSError):
                    self._file.stream.close()
        return self.folder

    def __enter__(self) -> McapBagWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
