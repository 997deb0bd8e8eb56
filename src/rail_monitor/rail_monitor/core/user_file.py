"""A file a user named, opened safely: anything wrong with it is one line naming it (no rclpy).

Every reader of a user's text file (site and parameter files, manifests, a bag's metadata.yaml,
detector and station CSVs) comes through here, so each refuses the same things the same way: a
missing file, a folder, a pipe or a device (reading one could block for ever or never end), a
symbolic-link loop, a file larger than what it can hold (a sparse file of gigabytes must not be
read into memory), and text that is not UTF-8 (named by line and byte).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from rail_monitor.core.errors import InputError, RailMonitorError

MAX_DOCUMENT_BYTES = 64 << 20  # a site file is a few kB; a bag's metadata.yaml lists ~200 B per file
MAX_TABLE_BYTES = 1 << 30      # a detector CSV: about 100 B a pass, ten million passes


def _why_not(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def regular_file(path: str | Path, what: str, error: type[RailMonitorError] = InputError) -> os.stat_result:
    """path's status, refused with one line unless it is a regular file (links followed)."""
    path = Path(path)
    try:
        st = path.stat()
    except FileNotFoundError:
        raise error(f"{path}: no such file") from None
    except OSError as exc:  # a link loop, a name too long, no permission on a folder
        raise error(f"{path}: cannot read {what}: {_why_not(exc)}") from None
    if stat.S_ISDIR(st.st_mode):
        raise error(f"{path}: is a folder; expected {what}")
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{path}: not a regular file (a pipe, socket or device); expected {what}")
    return st


def read_user_bytes(path: str | Path, what: str, max_bytes: int = MAX_DOCUMENT_BYTES,
                    error: type[RailMonitorError] = InputError) -> bytes:
    """The bytes of a user's file, at most max_bytes (a larger file is refused, not read)."""
    path = Path(path)
    st = regular_file(path, what, error)
    if st.st_size > max_bytes:
        raise error(f"{path}: {st.st_size} bytes, more than {what} may hold ({max_bytes} bytes)")
    try:
        with open(path, "rb") as fh:
            data = fh.read(max_bytes + 1)  # a file growing while read is still bounded
    except OSError as exc:
        raise error(f"{path}: cannot read {what}: {_why_not(exc)}") from None
    if len(data) > max_bytes:
        raise error(f"{path}: more than {what} may hold ({max_bytes} bytes)")
    return data


def read_user_text(path: str | Path, what: str, max_bytes: int = MAX_DOCUMENT_BYTES,
                   error: type[RailMonitorError] = InputError) -> str:
    """A user's file as text: UTF-8, a byte-order mark dropped; other text names its line and byte."""
    raw = read_user_bytes(path, what, max_bytes, error)
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise error(f"{path}: line {line}: not UTF-8 text (byte {raw[exc.start]:#04x}); save it as UTF-8") from None
