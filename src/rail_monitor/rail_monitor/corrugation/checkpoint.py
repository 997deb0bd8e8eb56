"""Checkpoints of a corrugation state: written atomically, resumed with a fallback to the
previous good file.

The file is a numpy .npz (zip members with CRCs): a JSON ``meta`` record (version, site, counts,
times), the band centres, ln Z of every component, K_b, the last survey and the post-grinding
amplitudes, and the kept passes' columns.
"""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.history import COLUMNS, KeptPasses

VERSION = 2
READABLE_VERSIONS = (1, 2)  # 1: before grinding_amplitude (read as the post-grinding default)
_COUNTS = ("pass_count", "axle_pass_count", "total_pass_count", "last_grinding_ns", "newest_ns", "last_survey_ns")


class CorruptCheckpoint(ConfigError):
    """A checkpoint file that cannot be read (truncated, failed CRC, missing arrays)."""


def previous_checkpoint(path: str | Path) -> Path:
    """Where save() keeps the checkpoint it replaced: the fallback when the newest is unreadable."""
    path = Path(path)
    return path.with_name(path.name + ".prev")


def save(est: CorrugationEstimator, path: str | Path) -> None:
    """Write the state atomically: a temporary file, fsync, rename over path, fsync the folder.

    The file it replaces is kept as previous_checkpoint(path). A crash between the two renames
    leaves only that one, which resume() then takes.
    """
    path = Path(path)
    meta = {"version": VERSION, "site_id": est.site.site_id, **{k: getattr(est, k) for k in _COUNTS},
            "newest_train_id": est.newest_train_id}
    buf = io.BytesIO()
    np.savez(buf, meta=np.array(json.dumps(meta)), bands=est.bands, log_components=est.log_components,
             k_b=est.k_b, survey_log_amplitude=est.survey_log_amplitude, grinding_amplitude=est.grinding_amplitude,
             **{f"recent_{n}": est.kept.train_id.astype(str) if n == "train_id" else getattr(est.kept, n)
                for n in COLUMNS})
    tmp = path.with_name(f".{path.name}.tmp")
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(tmp, "wb") as fh:
        fh.write(buf.getvalue())
        fh.flush()
        os.fsync(fh.fileno())
    if path.exists():  # keep the last good one: a later fault on the new file falls back to it
        os.replace(path, previous_checkpoint(path))
    os.replace(tmp, path)
    dir_fd = os.open(path.parent, os.O_RDONLY)
    try:
        os.fsync(dir_fd)
    finally:
        os.close(dir_fd)


def _read(path: str | Path) -> tuple[dict, dict[str, np.ndarray]]:
    """The meta record and the arrays of a checkpoint file (CorruptCheckpoint if unreadable)."""
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}  # zip member CRCs are checked as each is read
        meta = json.loads(str(data["meta"]))
        missing = {"bands", "log_components", "k_b", "survey_log_amplitude", *(f"recent_{n}" for n in COLUMNS)} \
            - set(data)
        if missing:
            raise KeyError(f"arrays missing: {', '.join(sorted(missing))}")
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such checkpoint") from None
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        raise CorruptCheckpoint(f"{path}: not a readable corrugation checkpoint: "
                                f"{(str(exc).splitlines() or [type(exc).__name__])[0]}") from None
    return meta, data


def load(est: CorrugationEstimator, path: str | Path) -> None:
    """Resume est from a checkpoint of its site with the same bands (ConfigError otherwise)."""
    meta, data = _read(path)
    if meta.get("version") not in READABLE_VERSIONS or meta.get("site_id") != est.site.site_id:
        raise ConfigError(f"{path}: checkpoint of site {meta.get('site_id')!r} version {meta.get('version')}, "
                          f"not of site {est.site.site_id!r} version {VERSION}")
    if data["bands"].shape != est.bands.shape or not np.allclose(data["bands"], est.bands) \
            or data["log_components"].shape != est.log_components.shape:
        raise ConfigError(f"{path}: checkpoint bands differ from the configured ones")
    est.log_components = data["log_components"].astype(float)
    est.survey_log_amplitude = data["survey_log_amplitude"].astype(float)
    est.grinding_amplitude = data.get("grinding_amplitude", est.post_grinding).astype(float)
    for key in _COUNTS:
        setattr(est, key, int(meta[key]))
    est.newest_train_id = str(meta.get("newest_train_id", ""))
    cols = {n: data[f"recent_{n}"] for n in COLUMNS}
    cols["train_id"] = cols["train_id"].astype(object)
    est.kept = KeptPasses(**cols)
    est.set_k_b(data["k_b"])


def resume(est: CorrugationEstimator, path: str | Path) -> tuple[Path | None, list[str]]:
    """Load the newest readable checkpoint: path, else previous_checkpoint(path).

    Returns the file loaded (None: neither exists, the state stays as it is) and one line per
    unreadable file passed over. Both unreadable is CorruptCheckpoint: a restart from zero
    would silently lose the history. A readable checkpoint of another site or other bands is
    ConfigError, with no fallback (the configuration is wrong, not the file).
    """
    skipped: list[str] = []
    for candidate in (Path(path), previous_checkpoint(path)):
        if not candidate.exists():
            continue
        try:
            load(est, candidate)
        except CorruptCheckpoint as exc:
            skipped.append(str(exc))
            continue
        return candidate, skipped
    if skipped:
        raise CorruptCheckpoint("; ".join(skipped) + " (and no readable previous checkpoint)")
    return None, skipped
