"""Every reader of a user's file fed one list of hostile inputs (issue 52: "every reader of a user's
file maps any exception it can raise to one line naming the file and what is wrong").

The readers: site and parameter files, a Dask manifest (YAML; a JSON document is YAML too), the
detector and station CSVs, a bag (its index, its metadata.yaml, salvage, its stored site), a
checkpoint, a WAV recording, a trolley's trace, and the command line over them. Each hostile
content is given under the name each reader expects (``.yaml``, ``.csv``, ``.mcap``, ``.wav``, a bag
folder's ``metadata.yaml``); the special files (a folder, a pipe, a sparse 8 GiB file, a link loop,
a dangling link, nothing) under the same names.

What holds for every pair: the reader raises RailMonitorError, or (salvage only, whose point is to
read past a damaged index) returns; the error is one printable line naming the file; nothing hangs
(an alarm turns a hang into a failure); the file is unchanged.
"""

from __future__ import annotations

import contextlib
import copy
import functools
import hashlib
import io
import os
import random
import shutil
import signal
import tempfile
from collections.abc import Callable
from pathlib import Path

import pytest

from rail_monitor.bagio import reader
from rail_monitor.bagio.csv_io import read_csv, read_csv_rows
from rail_monitor.bagio.measured_csv import read_measured_csv
from rail_monitor.bagio.passes_bag import write_passes_bag
from rail_monitor.bagio.site_record import read_site_record
from rail_monitor.bagio.trace_csv import read_trace
from rail_monitor.bagio.wav import read_wav
from rail_monitor.batch.sites import read_manifest
from rail_monitor.cli import main
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.text import printable
from rail_monitor.engine import checkpoint
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.site_file import check_parameter_file, load_parameter_file, load_site
from rail_monitor.station.archive import read_index

from conftest import EXAMPLE_CSV, SAMPLE, SITE_FILE

_RNG = random.Random(52)


def _alias_bomb() -> bytes:
    """Ten levels of nine aliases each: 9**10 values once expanded ("billion laughs")."""
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x]"]
    lines += [f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 9)}]" for i in range(1, 10)]
    return "\n".join(lines).encode()


CONTENTS: dict[str, bytes] = {
    "empty": b"",
    "NUL bytes": b"\0" * 1024,
    "random bytes": bytes(_RNG.getrandbits(8) for _ in range(4096)),
    "not UTF-8": b"time_utc,train_id\n\xff\xfe\x00\n",
    "UTF-16": "time_utc,train_id\n2020-01-01T00:00:00Z,a\n".encode("utf-16"),
    "a byte-order mark alone": b"\xef\xbb\xbf",
    "one 2 MiB line": b"a" * (2 << 20),
    "lines ended by CR alone": b"time_utc,train_id\r2020-01-01T00:00:00Z,a\r",
    "lists nested 20,000 deep": b"[" * 20_000,
    "mappings nested 5,000 deep": b"{a: " * 5_000 + b"1" + b"}" * 5_000,
    "an alias bomb": _alias_bomb(),
    "a self-referring alias": b"a: &a [*a]\n",
    "a python tag": b"!!python/object/apply:os.system ['true']\n",
    "an integer of 5,000 digits": b"/**:\n  ros__parameters:\n    site:\n      radius_m: " + b"9" * 5000 + b"\n",
    "JSON with NaN": b'{"/**": {"ros__parameters": {"site": {"radius_m": NaN}}}}',
    "terminal escapes in names": b"time_utc,\x1b[2J\x1b]0;x\x07,\xe2\x80\xae\ndata\n",
    "MCAP magic then garbage": b"\x89MCAP0\r\n" + bytes(_RNG.getrandbits(8) for _ in range(512)),
    "MCAP magic then zeros": b"\x89MCAP0\r\n" + b"\0" * 4096,
    "a bag's first 3 kB": (SAMPLE / "sample_0.mcap").read_bytes()[:3000],
}
SPECIAL = ("a folder", "a pipe", "a sparse 8 GiB file", "a link loop", "a dangling link", "nothing")


def _special(path: Path, kind: str) -> None:
    if kind == "a folder":
        path.mkdir()
    elif kind == "a pipe":
        os.mkfifo(path)
    elif kind == "a sparse 8 GiB file":
        with open(path, "wb") as fh:
            fh.write(b"\x89MCAP0\r\n")
            fh.truncate(8 << 30)
    elif kind == "a link loop":
        path.symlink_to(path.name)
    elif kind == "a dangling link":
        path.symlink_to("nowhere")


@functools.cache
def small_bag() -> Path:
    """The example CSV's 194 passes as a bag (made once: the readers' time goes to the hostile part)."""
    return write_passes_bag(read_csv(EXAMPLE_CSV), Path(tempfile.mkdtemp()) / "small", "site")


def _bag_folder(folder: Path, metadata: bytes) -> Path:
    """A whole bag's file beside a hostile metadata.yaml."""
    folder.mkdir()
    shutil.copy(small_bag() / "small_0.mcap", folder / f"{folder.name}_0.mcap")
    (folder / "metadata.yaml").write_bytes(metadata)
    return folder


def hostile_files(root: Path, suffix: str) -> dict[str, Path]:
    """Every hostile input under a name ending in suffix ("" for a bag folder's metadata.yaml)."""
    out = {}
    for i, (name, data) in enumerate(CONTENTS.items()):
        if suffix:
            out[name] = root / f"h{i}{suffix}"
            out[name].write_bytes(data)
        else:
            out[f"metadata.yaml: {name}"] = _bag_folder(root / f"bag{i}", data)
    for i, kind in enumerate(SPECIAL):
        out[kind] = root / f"s{i}{suffix or '.mcap'}"
        _special(out[kind], kind)
    return out


@functools.cache
def _estimator():
    """The shipped site's estimator on two wavelength bands (its tables take a second, not ten: every
    hostile file is refused before its bands are compared)."""
    from rail_monitor.corrugation.estimator import CorrugationEstimator

    values = {**load_parameter_file(SITE_FILE), "corrugation.shortest_wavelength_m": 0.05,
              "corrugation.longest_wavelength_m": 0.063}
    config = SiteConfig.from_values(values)
    return CorrugationEstimator(config.site, config.corrugation)


READERS: dict[str, tuple[tuple[str, ...], Callable[[Path], object]]] = {
    "site file": ((".yaml",), load_site),
    "parameter file": ((".yaml",), check_parameter_file),
    "manifest": ((".yaml",), read_manifest),
    "detector CSV": ((".csv",), read_csv_rows),
    "station CSV": ((".csv",), read_measured_csv),
    "bag": ((".mcap", ""), reader.read_passes),
    "bag info": ((".mcap", ""), reader.bag_info),
    "bag salvage": ((".mcap", ""), reader.salvage_bag_passes),
    "bag's stored site": ((".mcap", ""), read_site_record),
    "checkpoint": ((".npz",), lambda p: checkpoint.resume(copy.deepcopy(_estimator()), p)),
    "WAV": ((".wav",), read_wav),
    "trolley trace": ((".csv",), read_trace),
    "station's archive index": ((".json",), read_index),
}
MAY_RETURN = {"bag salvage", "bag's stored site"}  # salvage reads past metadata; a bag may hold no site


class _Hang(Exception):
    pass


@contextlib.contextmanager
def _alarm(seconds: int):
    def ring(*_):
        raise _Hang(f"no answer in {seconds} s")

    old = signal.signal(signal.SIGALRM, ring)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _digest(path: Path) -> str | None:
    if path.is_file() and not path.is_symlink() and path.stat().st_size < (64 << 20):
        return hashlib.sha256(path.read_bytes()).hexdigest()
    if path.is_dir():
        return ",".join(f"{p.name}:{_digest(p)}" for p in sorted(path.iterdir()))
    return None


def _named(message: str, path: Path) -> bool:
    return path.name in message or (path.parent.name in message and path.name == "metadata.yaml")


@pytest.mark.parametrize("what", sorted(READERS))
def test_every_reader_turns_every_hostile_input_into_one_line_naming_the_file(what, tmp_path):
    suffixes, read = READERS[what]
    faults = []
    for suffix in suffixes:
        root = tmp_path / (suffix.strip(".") or "folder")
        root.mkdir()
        for name, path in hostile_files(root, suffix).items():
            before = _digest(path)
            try:
                with _alarm(30):
                    read(path)
                fresh_start = what == "checkpoint" and name == "nothing"  # no checkpoint yet: documented
                if what not in MAY_RETURN and not name.startswith("metadata.yaml: ") and not fresh_start:
                    faults.append(f"{name}{suffix}: read without an error")
            except RailMonitorError as exc:
                message = str(exc)
                if "\n" in message or "\r" in message or (not _named(message, path) and path.name not in message):
                    faults.append(f"{name}{suffix}: not one line naming {path.name}: {message!r}")
            except BaseException as exc:  # any other exception is the fault looked for
                faults.append(f"{name}{suffix}: {type(exc).__name__}: {str(exc)[:200]}")
            if _digest(path) != before:
                faults.append(f"{name}{suffix}: the file changed")
    assert not faults, "\n".join(faults)


def test_a_bag_folder_with_a_hostile_metadata_file_is_refused_by_the_strict_readers(tmp_path):
    """The strict readers refuse each; salvage reads the intact file beside it."""
    folders = hostile_files(tmp_path, "")
    for name, folder in folders.items():
        if not name.startswith("metadata.yaml: "):
            continue
        with pytest.raises(RailMonitorError):
            reader.read_passes(folder)
        table, report = reader.salvage_bag_passes(folder)
        assert report.passes == len(table) == 194, name


COMMANDS: dict[str, tuple[str, Callable[[Path, Path], list[str]]]] = {
    "info": (".mcap", lambda p, out: ["info", str(p)]),
    "info --salvage": (".mcap", lambda p, out: ["info", "--salvage", str(p)]),
    "batch of a CSV": (".csv", lambda p, out: ["batch", str(p), "--no-report", "--output", str(out)]),
    "batch --measured": (".csv", lambda p, out: ["batch", str(small_bag()), "--measured", str(p), "--no-report",
                                                 "--output", str(out)]),
    "batch --site": (".yaml", lambda p, out: ["batch", str(small_bag()), "--site", str(p), "--no-report",
                                              "--output", str(out)]),
    "batch --manifest": (".yaml", lambda p, out: ["batch", "--manifest", str(p)]),
    "site --site": (".yaml", lambda p, out: ["site", "--site", str(p), str(out)]),
    "measure passby": (".wav", lambda p, out: ["measure", "passby", str(p), "--sensitivity", "1"]),
    "measure roughness": (".csv", lambda p, out: ["measure", "roughness", str(p)]),
    "batch --surveys": (".mcap", lambda p, out: ["batch", str(small_bag()), "--surveys", str(p), "--no-report",
                                                 "--output", str(out)]),
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_the_command_line_prints_one_line_and_exits_2_on_every_hostile_input(command, tmp_path, capsys):
    suffix, argv = COMMANDS[command]
    faults = []
    for name, path in hostile_files(tmp_path, suffix).items():
        out = tmp_path / f"out_{abs(hash(name))}"
        with _alarm(60), contextlib.redirect_stdout(io.StringIO()):
            try:
                code = main(argv(path, out))
            except SystemExit as exc:  # argparse
                code = exc.code
            except BaseException as exc:
                code = f"{type(exc).__name__}: {str(exc)[:200]}"
        err = capsys.readouterr().err.strip().splitlines()
        if command == "info --salvage" and code == 0:
            continue  # salvage reads what is intact (possibly nothing)
        if code != 2 or len(err) != 1 or not err[0].startswith("rail-monitor: error: ") or err[0] != printable(err[0]):
            faults.append(f"{name}: exit {code}, stderr {err[:3]!r}")
        if out.exists():
            faults.append(f"{name}: left {out.name} behind")
    assert not faults, "\n".join(faults)
