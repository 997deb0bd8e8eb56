"""Arrays worth keeping between commands, on disk: the per-site tables that take a second or more
to build (the track receptance, the corrugation growth table), keyed by everything they depend on
and the software version.

The folder is ``$RAIL_MONITOR_CACHE``, else ``$XDG_CACHE_HOME/rail_monitor``, else
``~/.cache/rail_monitor``. An entry is a folder of ``.npy`` files and a ``key`` file naming its key,
built aside and renamed into place whole. Arrays are read back as read-only memory maps: a process
holds in memory only the pages it touches (a live node looking up a few passes in the 24 MB
growth table holds a few kB of it, and processes on one machine share the pages). An entry that
cannot be read or names another key is rebuilt and replaced (only entries holding nothing but
this cache's files are ever replaced). A folder that cannot be written (a read-only home) only
means no cache.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor import __version__

KEY_FILE = "key"


def cache_folder() -> Path:
    if os.environ.get("RAIL_MONITOR_CACHE"):
        return Path(os.environ["RAIL_MONITOR_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "rail_monitor"


def cache_key(kind: str, inputs: dict[str, Any]) -> str:
    """SHA-256 of the kind, the inputs (as JSON, floats exactly) and the software version."""
    text = json.dumps({"kind": kind, "version": __version__, "inputs": inputs}, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()


def cached_arrays(kind: str, inputs: dict[str, Any],
                  build: Callable[[], dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """build()'s arrays, from the cache when an entry for exactly these inputs exists (then
    read-only, mapped from the files)."""
    key = cache_key(kind, inputs)
    entry = cache_folder() / f"{kind}_{key[:24]}"
    got = _read(entry, key)
    if got is not None:
        return got
    arrays = build()
    with contextlib.suppress(OSError):  # no cache where the folder cannot be written
        _write(entry, key, arrays)
        got = _read(entry, key)
    return arrays if got is None else got


def _read(entry: Path, key: str) -> dict[str, np.ndarray] | None:
    """The arrays of a complete entry for this key, else None."""
    try:
        if (entry / KEY_FILE).read_text() != key:
            return None
        # np.asarray: a plain ndarray view of the map (a np.memmap would tag every result).
        return {p.stem: np.asarray(np.load(p, mmap_mode="r", allow_pickle=False)) for p in entry.glob("*.npy")}
    except (OSError, ValueError, EOFError):  # none yet, unreadable, or cut short: rebuild
        return None


def _ours(entry: Path) -> bool:
    """Whether a folder holds only files this cache writes."""
    return all(p.is_file() and (p.suffix == ".npy" or p.name == KEY_FILE) for p in entry.iterdir())


def _write(entry: Path, key: str, arrays: dict[str, np.ndarray]) -> None:
    """Write the entry aside, then rename it into place (replacing a stale entry of ours)."""
    entry.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{entry.name}_", dir=entry.parent))
    try:
        for name, array in arrays.items():
            np.save(tmp / f"{name}.npy", array, allow_pickle=False)
        (tmp / KEY_FILE).write_text(key)  # last: an entry naming its key is complete
        if entry.exists():
            if _read(entry, key) is not None or not _ours(entry):
                return  # written by another process meanwhile, or not ours to replace
            stale = Path(tempfile.mkdtemp(prefix=f".{entry.name}_stale_", dir=entry.parent))
            os.rename(entry, stale / "entry")
            _remove(stale / "entry")
            stale.rmdir()
        os.rename(tmp, entry)
    finally:
        if tmp.exists():
            _remove(tmp)


def _remove(folder: Path) -> None:
    """Delete a folder of this cache's files (nothing else is in it: see _ours)."""
    for p in folder.iterdir():
        p.unlink()
    folder.rmdir()
