"""Retention of a long recording: which finished split files to delete to stay within a disk
budget and an age limit (pure arithmetic; the bag writer does the deleting)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from rail_monitor.core.errors import RailMonitorError

# What a file's summary (indexes, statistics, metadata) may add past its last chunk, and what
# metadata.yaml and the marker take [bytes].
SUMMARY_ALLOWANCE = 64 * 1024
_BLOCK = 4096  # files take whole blocks of the file system


def on_disk(size: int) -> int:
    """Bytes a file of size bytes takes on disk (whole blocks)."""
    return -(-size // _BLOCK) * _BLOCK


@dataclass(frozen=True)
class Retention:
    """max_total_bytes: the budget of the bag's files [bytes]; max_age_ns: the oldest a finished
    file's last message may be before the newest message [ns]; open_allowance: what the open file
    may reach before it splits [bytes] (0 for each: no limit)."""

    max_total_bytes: int = 0
    max_age_ns: int = 0
    open_allowance: int = 0

    @classmethod
    def checked(cls, max_total_bytes: int, max_age_ns: int, max_file_bytes: int, max_file_duration_ns: int,
                chunk_size: int) -> Retention:
        """RailMonitorError for settings that cannot hold: a budget needs files split by size (at
        least twice what the open file may reach), an age needs files split at all."""
        allowance = on_disk(max_file_bytes + chunk_size + SUMMARY_ALLOWANCE)
        if max_total_bytes and (not max_file_bytes or max_total_bytes < 2 * allowance + SUMMARY_ALLOWANCE):
            raise RailMonitorError(f"a disk budget of {max_total_bytes} bytes needs files split by size, and at "
                                   f"least twice (split size + chunk size + {SUMMARY_ALLOWANCE}) plus "
                                   f"{SUMMARY_ALLOWANCE} = {2 * allowance + SUMMARY_ALLOWANCE} bytes")
        if max_age_ns and not (max_file_bytes or max_file_duration_ns):
            raise RailMonitorError("an age limit needs files split by size or by duration")
        return cls(max_total_bytes, max_age_ns, allowance)

    def oldest_to_delete(self, sizes: Sequence[int], last_ns: Sequence[int], newest_ns: int,
                         file_open: bool) -> int:
        """How many of the finished files (oldest first: sizes [bytes], last message [ns]) to
        delete: those past the age limit, then the oldest until the rest fit the budget less the
        open file's allowance (when one is open) and metadata.yaml's share."""
        room = self.max_total_bytes - (self.open_allowance if file_open else 0) - SUMMARY_ALLOWANCE
        kept = sum(on_disk(s) for s in sizes)
        n = 0
        while n < len(sizes) and ((self.max_age_ns and last_ns[n] < newest_ns - self.max_age_ns)
                                  or (self.max_total_bytes and kept > room)):
            kept -= on_disk(sizes[n])
            n += 1
        return n
