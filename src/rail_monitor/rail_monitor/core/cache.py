"""Arrays worth keeping between commands, on disk: the per-site tables that take a second or more
to build (the track receptance), keyed by everything they depend on and the software version.

The folder is ``$RAIL_MONITOR_CACHE``, else ``$XDG_CACHE_HOME/rail_monitor``, else
``~/.cache/rail_monitor``. A file is written atomically and names its key inside; one that cannot
be read or holds another key is rebuilt and replaced (only files of this cache are ever
replaced). A folder that cannot be written (a read-only home) only means no cache.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor import __version__


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
    """build()'s arrays, from the cache when a file for exactly these inputs exists."""
    key = cache_key(kind, inputs)
    path = cache_folder() / f"{kind}_{key[:24]}.npz"
    try:
        with np.load(path, allow_pickle=False) as f:
            if str(f["_key"]) == key:
                return {k: f[k] for k in f.files if k != "_key"}
    except (OSError, ValueError, KeyError, EOFError):  # none yet, unreadable, or another key: rebuild
        pass
    arrays = build()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{kind}_", suffix=".npz", dir=path.parent)
        with os.fdopen(fd, "wb") as out:
            np.savez(out, _key=np.array(key), **arrays)
        os.replace(tmp, path)
    except OSError:
        pass  # no cache where the folder cannot be written
    return arrays
