"""A write-only file with no user-space buffer: what a killed writer wrote is on disk."""

from __future__ import annotations

import contextlib
import os
from pathlib import Path


class DirectFile:
    """A write-only file whose every write reaches the OS at once (no user-space buffer), so a
    killed writer leaves on disk everything it wrote. Not a RawIOBase, which mcap would wrap in
    a BufferedWriter."""

    def __init__(self, path: Path) -> None:
        self._fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        self._pos = 0

    def write(self, data: bytes | memoryview) -> int:
        view = memoryview(data)
        try:
            while view:
                view = view[os.write(self._fd, view):]
        except OSError:
            # A full disk or a write error: cut off what got out of this write, so the file stays
            # the records written before it (a salvage reads them all), then report.
            with contextlib.suppress(OSError):
                os.ftruncate(self._fd, self._pos)
                os.lseek(self._fd, self._pos, os.SEEK_SET)
            raise
        self._pos += len(data)
        return len(data)

    def tell(self) -> int:
        return self._pos

    def flush(self) -> None:
        pass

    def fileno(self) -> int:
        return self._fd

    def close(self) -> None:
        os.close(self._fd)
