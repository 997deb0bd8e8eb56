"""Checkpoints of a corrugation state: written atomically, resumed with a fallback to the
previous good file.

The file is a numpy .npz (zip members with CRCs): a JSON ``meta`` record (version, site, counts,
times), the band centres, ln Z of every component, K_b, the last survey and the post-grinding
amplitudes, the calibration (growth since the last survey per friction state, the covariance of
ln K_b, the bands' levels' covariance with each other and with ln K_b), the last year's growth and
passes per day and friction state, and the kept passes' columns;
with an indirect roughness observer (rail_monitor.measured.observer), its open window's fit too
(optional arrays ``indirect_*``: a file without them resumes with the window empty); with the
squeal model's fit (rail_monitor.engine.squeal_site), its grids, posteriors and passes (optional
arrays ``squeal_fit_*``: a file without them resumes on the configured curves).
"""

from __future__ import annotations

import copy
import io
import json
import os
import threading
import zipfile
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.user_file import regular_file
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.history import COLUMNS, KeptPasses
from rail_monitor.corrugation.season import DailyGrowth
from rail_monitor.models import calibration

if TYPE_CHECKING:  # the observer's module imports the noise model: not needed to read a checkpoint
    from rail_monitor.engine.squeal_site import SquealSite
    from rail_monitor.measured.observer import IndirectObserver

VERSION = 6
# 1: before grinding_amplitude (read as the post-grinding default); 1-2: before the contact regime
# (their kept passes read as in partial slip, at their class's nominal load, as they were counted);
# 1-3: before the calibration (read as the prior about their K_b, no growth since the last survey,
# each band's level known to the post-grinding uncertainty); 1-4: before the daily growth of the
# last year (read as none: the forecast interval uses the recent window until a year has passed);
# 4-5: before the levels' covariance (read as each band's variance alone, uncorrelated with K_b);
# 5: before the daily passes per friction state (the daily growth read as none, as 1-4).
READABLE_VERSIONS = (1, 2, 3, 4, 5, 6)
CALIBRATION_ARRAYS = ("growth_by_state", "calibration_cov", "level_cov", "level_kb_cov")
CALIBRATION_ARRAYS_4 = ("growth_by_state", "calibration_cov", "level_var")  # versions 4-5
SEASON_ARRAYS = ("season_growth", "season_passes", "season_first_day")
CONTACT_COLUMNS = ("regime", "load", "creepage")
_COUNTS = ("pass_count", "axle_pass_count", "total_pass_count", "last_grinding_ns", "newest_ns", "last_survey_ns")


class CorruptCheckpoint(ConfigError):
    """A checkpoint file that cannot be read (truncated, failed CRC, missing arrays)."""


def previous_checkpoint(path: str | Path) -> Path:
    """Where save() keeps the checkpoint it replaced: the fallback when the newest is unreadable."""
    path = Path(path)
    return path.with_name(path.name + ".prev")


def save(est: CorrugationEstimator, path: str | Path, observer: IndirectObserver | None = None,
         squeal: SquealSite | None = None) -> None:
    """Write the state atomically (snapshot, encode, write_atomically)."""
    write_atomically(encode(snapshot(est, observer, squeal)), path)


def snapshot(est: CorrugationEstimator, observer: IndirectObserver | None = None,
             squeal: SquealSite | None = None) -> dict[str, np.ndarray]:
    """The state's arrays now, copied and not yet converted (the cheap part: the state may move on
    while another thread encodes them)."""
    meta = {"version": VERSION, "site_id": est.site.site_id, **{k: getattr(est, k) for k in _COUNTS},
            "newest_train_id": est.newest_train_id, "calibration_fits": est.calibration.fits}
    arrays = dict(meta=np.array(json.dumps(meta)), bands=est.bands, log_components=est.log_components,
                  k_b=est.k_b, survey_log_amplitude=est.survey_log_amplitude,
                  grinding_amplitude=est.grinding_amplitude, growth_by_state=est.growth_by_state,
                  calibration_cov=est.calibration.cov, level_cov=est.level_cov, level_kb_cov=est.level_kb_cov,
                  calibration_mean=est.calibration.mean, season_growth=est.season.growth,
                  season_passes=est.season.passes, season_first_day=np.array(est.season.first_day),
                  **{f"recent_{n}": getattr(est.kept, n) for n in COLUMNS},
                  **(observer.to_arrays() if observer is not None else {}),
                  **(squeal.to_arrays() if squeal is not None else {}))
    return {name: np.array(a, copy=True) for name, a in arrays.items()}


def encode(arrays: dict[str, np.ndarray]) -> bytes:
    """A snapshot's checkpoint file (.npz) bytes: the kept train ids as text, every array as written."""
    buf = io.BytesIO()
    np.savez(buf, **{name: a.astype(str) if a.dtype == object else a for name, a in arrays.items()})
    return buf.getvalue()


def write_atomically(data: bytes, path: str | Path) -> None:
    """Write a checkpoint file's bytes atomically: a temporary file, fsync, rename over path, fsync
    the folder. The file it replaces is kept as previous_checkpoint(path); a crash between the two
    renames leaves only that one, which resume() then takes."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp")
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(tmp, "wb") as fh:
        fh.write(data)
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


class CheckpointWriter:
    """Writes checkpoints on a thread of its own, so that the thread advancing the state (a node's
    executor) only copies it (snapshot); the encoding and the atomic write happen here. The newest
    snapshot submitted is written, an older one still waiting is replaced by it (coalesced). One
    thread and one file: writes never overlap.

    on_written(snapshot) and on_error(exc) are called on the writer's thread after each write.
    """

    def __init__(self, path: str | Path, on_written=None, on_error=None) -> None:
        self.path = Path(path)
        self.on_written = on_written or (lambda data: None)
        self.on_error = on_error or (lambda exc: None)
        self.written = self.failed = self.coalesced = 0
        self._waiting: dict[str, np.ndarray] | None = None
        self._busy = False
        self._closed = False
        self._cond = threading.Condition()
        self._thread = threading.Thread(target=self._run, name="checkpoint writer", daemon=True)
        self._thread.start()

    def submit(self, data: dict[str, np.ndarray]) -> None:
        """Queue a snapshot (replacing any not yet begun)."""
        with self._cond:
            if self._closed:
                raise RuntimeError("checkpoint writer closed")
            self.coalesced += self._waiting is not None
            self._waiting = data
            self._cond.notify_all()

    def flush(self, timeout_s: float | None = None) -> bool:
        """Wait until every checkpoint submitted so far is written (or failed); whether it was."""
        with self._cond:
            return self._cond.wait_for(lambda: self._waiting is None and not self._busy, timeout_s)

    def close(self, timeout_s: float | None = None) -> bool:
        """Write what is waiting, then stop the thread; whether it finished in time."""
        done = self.flush(timeout_s)
        with self._cond:
            self._closed = True
            self._cond.notify_all()
        self._thread.join(timeout_s)
        return done and not self._thread.is_alive()

    def _run(self) -> None:
        while True:
            with self._cond:
                self._cond.wait_for(lambda: self._waiting is not None or self._closed)
                if self._waiting is None:
                    return
                data, self._waiting, self._busy = self._waiting, None, True
            try:
                write_atomically(encode(data), self.path)
            except OSError as exc:
                self.failed += 1
                self.on_error(exc)
            else:
                self.written += 1
                self.on_written(data)
            finally:
                with self._cond:
                    self._busy = False
                    self._cond.notify_all()


def _read(path: str | Path) -> tuple[dict, dict[str, np.ndarray]]:
    """The meta record and the arrays of a checkpoint file (CorruptCheckpoint if unreadable)."""
    if not Path(path).exists():
        raise ConfigError(f"{path}: no such checkpoint")
    regular_file(path, "a checkpoint", CorruptCheckpoint)  # np.load would wait on a pipe for ever
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}  # zip member CRCs are checked as each is read
        meta = json.loads(str(data["meta"]))
        version = meta.get("version") if isinstance(meta, dict) else None
        wanted = COLUMNS if version in (3, 4, 5, VERSION) else tuple(n for n in COLUMNS if n not in CONTACT_COLUMNS)
        calibrated = CALIBRATION_ARRAYS if version == VERSION else CALIBRATION_ARRAYS_4
        missing = {"bands", "log_components", "k_b", "survey_log_amplitude", *(f"recent_{n}" for n in wanted),
                   *(calibrated if version in (4, 5, VERSION) else ()),
                   *(SEASON_ARRAYS if version in (5, VERSION) else ())} - set(data)
        if missing:
            raise KeyError(f"arrays missing: {', '.join(sorted(missing))}")
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such checkpoint") from None
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        raise CorruptCheckpoint(f"{path}: not a readable corrugation checkpoint: "
                                f"{(str(exc).splitlines() or [type(exc).__name__])[0]}") from None
    return meta, data


def load(est: CorrugationEstimator, path: str | Path, observer: IndirectObserver | None = None,
         squeal: SquealSite | None = None) -> None:
    """Resume est (and observer's window and squeal's fit, where the file has them) from a
    checkpoint of its site with the same bands (ConfigError otherwise; a file that does not hold a
    whole, consistent state is CorruptCheckpoint). All are changed only once the whole file has
    been read and checked."""
    meta, data = _read(path)
    if not isinstance(meta, dict):
        raise CorruptCheckpoint(f"{path}: not a readable corrugation checkpoint: its meta record is not a mapping")
    if meta.get("version") not in READABLE_VERSIONS or meta.get("site_id") != est.site.site_id:
        raise ConfigError(f"{path}: checkpoint of site {meta.get('site_id')!r} version {meta.get('version')}, "
                          f"not of site {est.site.site_id!r} version {VERSION}")
    try:
        state = _state(est, meta, data)
    except (TypeError, ValueError, KeyError, AttributeError, IndexError, OverflowError) as exc:
        raise CorruptCheckpoint(f"{path}: not a readable corrugation checkpoint: {type(exc).__name__}: "
                                f"{(str(exc).splitlines() or [''])[0]}") from None
    if state is None:
        raise ConfigError(f"{path}: checkpoint bands differ from the configured ones")
    trials = []
    for part in (p for p in (observer, squeal) if p is not None):
        trial = copy.copy(part)
        try:
            trial.restore(data)
        except (TypeError, ValueError, KeyError) as exc:
            raise CorruptCheckpoint(f"{path}: not a readable corrugation checkpoint: {exc}") from None
        trials.append((part, trial))
    for part, trial in trials:
        part.__dict__.update(trial.__dict__)
    k_b = state.pop("_k_b")
    for key, value in state.items():
        setattr(est, key, value)
    est.set_k_b(k_b)


def _state(est: CorrugationEstimator, meta: dict, data: dict[str, np.ndarray]) -> dict | None:
    """The estimator's attributes from a checkpoint's records, every array checked (None: other bands)."""
    bands = np.asarray(data["bands"], float)
    log_components = np.asarray(data["log_components"], float)
    if bands.shape != est.bands.shape or not np.allclose(bands, est.bands) \
            or log_components.shape != est.log_components.shape:
        return None
    k_b = np.asarray(data["k_b"], float)
    survey = np.asarray(data["survey_log_amplitude"], float)
    grinding = np.asarray(data.get("grinding_amplitude", est.post_grinding), float)
    nb = len(est.bands)
    if k_b.shape != (4,) or survey.shape != (nb,) or grinding.shape != (nb,):
        raise ValueError("K_b, survey or post-grinding arrays have the wrong shape")
    if not (np.all(np.isfinite(log_components)) and np.all(np.isfinite(k_b)) and np.all(k_b >= 0)
            and np.all(np.isfinite(grinding)) and np.all(grinding > 0)):
        raise ValueError("state arrays not finite, or K_b negative, or post-grinding amplitudes not positive")
    cols = {n: np.asarray(data[f"recent_{n}"]) for n in COLUMNS if f"recent_{n}" in data}
    cols["train_id"] = cols["train_id"].astype(str).astype(object)
    if "regime" not in cols:  # versions 1-2
        nominal = np.array([est.site.vehicle(c).wheel_load_n for c in est.tables.classes])
        cls = cols["class_idx"].astype(np.int64, casting="same_kind")
        cols.update(regime=np.zeros(len(cls), np.int64), load=nominal[np.clip(cls, 0, len(nominal) - 1)],
                    creepage=np.zeros(len(cls)))
    for n, dtype in (("stamp_ns", np.int64), ("class_idx", np.int64), ("friction", np.int64), ("axles", np.int64),
                     ("speed", np.float64), ("regime", np.int64), ("load", np.float64), ("creepage", np.float64)):
        cols[n] = cols[n].astype(dtype, casting="same_kind")
    n = len(cols["stamp_ns"])
    if any(c.ndim != 1 or len(c) != n for c in cols.values()):
        raise ValueError("kept-pass columns differ in length")
    if n and (cols["class_idx"].min() < 0 or cols["class_idx"].max() >= len(est.tables.classes)
              or cols["friction"].min() < 1 or cols["friction"].max() > 4 or not np.all(np.isfinite(cols["speed"]))
              or not np.all(np.isin(cols["regime"], (0, 1))) or not np.all(np.isfinite(cols["load"]))
              or not np.all(np.isfinite(cols["creepage"]))):
        raise ValueError("kept passes hold an unknown class, friction state, regime, speed, load or creepage")
    calibrated = _calibration(est, meta, data, k_b)
    season = DailyGrowth(est.log_components.shape)
    if "season_growth" in data and meta.get("version") == VERSION:
        season.growth = np.asarray(data["season_growth"], float)
        season.passes = np.asarray(data["season_passes"]).astype(np.int64, casting="same_kind")
        season.first_day = int(data["season_first_day"])
        if season.growth.shape != (len(season.passes), 4, *est.log_components.shape) or season.passes.ndim != 2 \
                or not np.all(np.isfinite(season.growth)) or np.any(season.passes < 0):
            raise ValueError("season arrays have the wrong shape, are not finite or count negative passes")
    counts = {key: int(meta[key]) for key in _COUNTS}
    if any(v < 0 for v in counts.values()):
        raise ValueError("negative counts")
    return {"log_components": log_components, "survey_log_amplitude": survey, "grinding_amplitude": grinding,
            **counts, "newest_train_id": str(meta.get("newest_train_id", "")), "kept": KeptPasses(**cols),
            **calibrated, "season": season, "_k_b": k_b}


def _calibration(est: CorrugationEstimator, meta: dict, data: dict[str, np.ndarray], k_b: np.ndarray) -> dict:
    """The calibration's attributes: from the file (version 4), else the prior about its K_b. The
    posterior mean is ln(K_b / the configured default), so a changed default keeps the fitted K_b."""
    default = est.cfg.k_b
    mean = np.log(np.divide(k_b, default, out=np.ones(4), where=(default > 0) & (k_b > 0)))
    if "calibration_mean" in data and np.allclose(data["calibration_mean"], mean, rtol=1e-9, atol=1e-12):
        mean = np.asarray(data["calibration_mean"], float)  # the bits, so a resumed fit equals an unbroken one
    if "calibration_cov" not in data:
        return {"growth_by_state": np.zeros_like(est.growth_by_state), "level_cov": np.diag(est.post_grinding_var),
                "level_kb_cov": np.zeros_like(est.level_kb_cov), "calibration": replace(est.calibration, mean=mean)}
    growth = np.asarray(data["growth_by_state"], float)
    cov = np.asarray(data["calibration_cov"], float)
    if "level_cov" in data:
        level_cov, cross = np.asarray(data["level_cov"], float), np.asarray(data["level_kb_cov"], float)
    else:  # versions 4-5
        level_cov, cross = np.diag(np.asarray(data["level_var"], float)), np.zeros_like(est.level_kb_cov)
    fits = int(meta.get("calibration_fits", 0))
    if growth.shape != est.growth_by_state.shape or cov.shape != (4, 4) or cross.shape != est.level_kb_cov.shape \
            or level_cov.shape != est.level_cov.shape:
        raise ValueError("calibration arrays have the wrong shape")
    joint = calibration.joint_cov(level_cov, cross, cov)
    if not (np.all(np.isfinite(growth)) and np.all(np.isfinite(joint)) and np.allclose(joint, joint.T) and fits >= 0):
        raise ValueError("calibration arrays not finite or covariances not symmetric")
    np.linalg.cholesky(joint)  # LinAlgError (a ValueError) unless positive definite, as every survey leaves it
    return {"growth_by_state": growth, "level_cov": level_cov, "level_kb_cov": cross,
            "calibration": calibration.KbPosterior(mean, cov, fits)}


def resume(est: CorrugationEstimator, path: str | Path, observer: IndirectObserver | None = None,
           squeal: SquealSite | None = None) -> tuple[Path | None, list[str]]:
    """Load the newest readable checkpoint: path, else previous_checkpoint(path).

    Returns the file loaded (None: neither exists, the state stays as it is) and one line per
    unreadable file passed over. Both unreadable is CorruptCheckpoint: a restart from zero
    would silently lose the history. A readable checkpoint of another site or other bands is
    ConfigError, with no fallback (the configuration is wrong, not the file).
    """
    skipped: list[str] = []
    for candidate in (Path(path), previous_checkpoint(path)):
        if candidate.is_symlink() and not candidate.exists():  # a disk not mounted: no fresh start
            raise ConfigError(f"{candidate}: a symbolic link to nothing (or a loop); the checkpoint it "
                              "stands for cannot be read, and a restart from zero would lose the history")
        if not candidate.exists():
            continue
        try:
            load(est, candidate, observer, squeal)
        except CorruptCheckpoint as exc:
            skipped.append(str(exc))
            continue
        return candidate, skipped
    if skipped:
        raise CorruptCheckpoint("; ".join(skipped) + " (and no readable previous checkpoint)")
    return None, skipped
