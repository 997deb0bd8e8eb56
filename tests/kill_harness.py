"""Crash consistency, proven by killing (issue 52): a writer is started in a forked child, killed
with SIGKILL after a seeded random delay, and what it left on disk is checked against what it had
reported before it died. Run as a script by tests/engine/test_checkpoint.py and
tests/bagio/test_mcap_bag.py (its own process: forking a process that holds other threads could
copy a lock held by one of them); prints one JSON object.

    python tests/kill_harness.py checkpoint|recorder KILLS SEED FOLDER

checkpoint: each child resumes a corrugation state from the checkpoint (rail_monitor.engine.
checkpoint.resume, as the estimator node does at start-up), counts the next sample passes through
the corrugation step (engine.corrugation_site) and submits a snapshot to the CheckpointWriter every
EVERY passes, reporting each snapshot's digest when submitted and again when written. After each
kill the parent resumes a fresh state as the node would: it must load, hold exactly one of the
states submitted, and be no older than the last one reported written. The replay goes on from
there, life after life; a child that finishes the history closes the writer and the next starts a
new history. The last full history's state is compared with an uninterrupted run's.

recorder: each child writes the sample passes as TrainPass messages into a new bag folder
(rail_monitor.bagio.mcap_bag.McapBagWriter, small chunks and split files, as the recorder node
does), flushing every FLUSH_EVERY messages and reporting the count flushed. After each kill the bag
must read strictly (rail_monitor.bagio.reader.read_passes) or be refused in one line, and salvage
(salvage_bag_passes) must give back at least every message reported flushed, each equal to the
one written, in order.
"""

from __future__ import annotations

import hashlib
import json
import os
import random
import shutil
import signal
import sys
import time
from pathlib import Path

import numpy as np

from rail_monitor.bagio.passes_bag import pass_cdr
from rail_monitor.bagio.reader import read_passes, salvage_bag_passes
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.passes import PassTable, rejection_reasons, with_class_defaults

TOP = Path(__file__).resolve().parents[1]
PASSES = 120           # of the sample, per checkpointed history
RECORDED = 240         # of the sample, per bag
STEP = 10              # passes per take (the node takes what arrived; 10 is a busy moment)
EVERY = 6              # passes between checkpoints (the node's default is 100; more writes, more chances)
FLUSH_EVERY = 50       # messages between flushes (the node flushes every flush_period_s)
LATE = 1.1             # a kill lands uniformly between the fork and LATE x an uninterrupted life


def _sample(n: int) -> PassTable:
    from rail_monitor.site_file import load_site

    site = load_site(TOP / "src" / "rail_monitor" / "config" / "curve_250.yaml")
    table = read_passes(TOP / "bags" / "sample").sorted()
    table = with_class_defaults(table.take(rejection_reasons(table, site) == ""), site)
    return table.take(slice(0, n))


def _digest(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = arrays[name].astype(str) if arrays[name].dtype == object else arrays[name]
        h.update(f"{name}{a.dtype.str}{a.shape}".encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _report(fd: int, *fields: object) -> None:
    os.write(fd, (" ".join(map(str, fields)) + "\n").encode())


def _timed_life(work) -> tuple[list[list[str]], float]:
    """An uninterrupted life: its lines and how long it took [s]."""
    t0 = time.monotonic()
    lines = _life(work, None)
    return lines, time.monotonic() - t0


def _life(work, kill_after_s: float | None) -> list[list[str]]:
    """Run work(fd) in a forked child, SIGKILL it after kill_after_s (None: let it finish); the
    lines it reported, split into fields."""
    read_fd, write_fd = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child
        os.close(read_fd)
        try:
            work(write_fd)
        finally:
            os._exit(0)
    os.close(write_fd)
    if kill_after_s is not None:
        time.sleep(kill_after_s)
        os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
    data = b""
    while chunk := os.read(read_fd, 1 << 16):
        data += chunk
    os.close(read_fd)
    return [line.split() for line in data.decode().splitlines()]


def checkpoints(kills: int, seed: int, folder: Path) -> dict:
    from rail_monitor.corrugation.estimator import CorrugationEstimator
    from rail_monitor.engine import checkpoint
    from rail_monitor.engine.corrugation_site import CorrugationSite
    from rail_monitor.engine.site_config import SiteConfig
    from rail_monitor.site_file import load_parameter_file

    config = SiteConfig.from_values(load_parameter_file(TOP / "src" / "rail_monitor" / "config" / "curve_250.yaml"))
    pristine = CorrugationEstimator(config.site, config.corrugation)
    passes = _sample(PASSES)
    path = folder / "corrugation.npz"

    def work(fd: int) -> None:
        est = pristine  # the child's own copy (fork)
        checkpoint.resume(est, path)
        start = int(np.searchsorted(passes.stamp_ns, est.newest_ns, side="right")) if est.pass_count else 0
        step = CorrugationSite(est)
        writer = checkpoint.CheckpointWriter(path, on_written=lambda d: _report(fd, "W", _digest(d)))
        since = 0
        for i in range(start, len(passes), STEP):
            step.advance(passes.take(slice(i, i + STEP)))
            since += min(STEP, len(passes) - i)
            if since >= EVERY or i + STEP >= len(passes):
                data = checkpoint.snapshot(est)
                _report(fd, "S", _digest(data), est.pass_count)
                writer.submit(data)
                since = 0
        writer.close()
        _report(fd, "DONE")

    def resumed(fd: int) -> None:  # in a child of its own: the parent's estimator stays pristine
        est = pristine
        try:
            used, skipped = checkpoint.resume(est, path)
        except RailMonitorError as exc:
            _report(fd, "ERROR", str(exc))
            return
        fell_back = bool(skipped) or (used is not None and used.name.endswith(".prev"))
        _report(fd, "R", _digest(checkpoint.snapshot(est)), est.pass_count, int(fell_back))

    whole, lifetime = _timed_life(work)  # uninterrupted: the state a full history must end in
    final = next(f[1] for f in reversed(whole) if f[0] == "S")
    for p in folder.iterdir():
        p.unlink()
    rng = random.Random(seed)
    order: dict[str, int] = {}  # digest submitted -> its position in the history's submissions
    last_written = -1
    faults: list[str] = []
    fallbacks = histories = 0
    at_kill: list[int] = []
    for k in range(kills):
        lines = _life(work, rng.uniform(0.0, LATE * lifetime))
        for f in lines:
            if f[0] == "S":
                order.setdefault(f[1], len(order))
            elif f[0] == "W":
                last_written = max(last_written, order[f[1]])
        loaded = _life(resumed, None)[0]
        if loaded[0] != "R":
            faults.append(f"kill {k}: the checkpoint does not load: {' '.join(loaded[1:])}")
            break
        digest, count, fell_back = loaded[1], int(loaded[2]), int(loaded[3])
        fallbacks += fell_back
        at_kill.append(count)
        if count and digest not in order:
            faults.append(f"kill {k}: loaded a state never submitted ({count} passes)")
        elif count and order[digest] < last_written:
            faults.append(f"kill {k}: loaded submission {order[digest]}, older than {last_written} reported written")
        elif not count and last_written >= 0:
            faults.append(f"kill {k}: loaded nothing after submission {last_written} was reported written")
        if any(f[0] == "DONE" for f in lines):  # a full history: it must end in the uninterrupted state
            histories += 1
            if digest != final:
                faults.append(f"kill {k}: a history resumed across kills ends in another state than one run")
            for p in folder.iterdir():
                p.unlink()
            order, last_written = {}, -1
    return {"kills": kills, "faults": faults, "fallbacks": fallbacks, "histories": histories, "life_s": lifetime,
            "passes_at_kill": at_kill}


def recordings(kills: int, seed: int, folder: Path) -> dict:
    from rail_monitor.bagio.mcap_bag import McapBagWriter
    from rail_monitor.codec.typestore import TRAIN_PASS

    passes = _sample(RECORDED)
    cdr = pass_cdr(passes, "kill_harness")
    rng = random.Random(seed)
    faults: list[str] = []
    strict = salvaged_total = flushed_total = split_files = 0

    def work(fd: int, bag: Path) -> None:
        writer = McapBagWriter(bag, chunk_size=4 << 10, max_file_bytes=24 << 10)
        writer.add_topic("/train_pass", TRAIN_PASS)
        for i in range(0, len(cdr), FLUSH_EVERY):
            writer.write_many("/train_pass", cdr[i:i + FLUSH_EVERY], passes.stamp_ns[i:i + FLUSH_EVERY].tolist())
            writer.flush()
            _report(fd, "F", writer.message_count)
        writer.close()
        _report(fd, "CLOSED")

    lifetime = float("inf")
    for _ in range(3):  # the shortest of three: a first life slowed by a busy machine would put most kills after close
        lifetime = min(lifetime, _timed_life(lambda fd: work(fd, folder / "uninterrupted"))[1])
        shutil.rmtree(folder / "uninterrupted")
    for k in range(kills):
        bag = folder / f"bag{k}"
        lines = _life(lambda fd, bag=bag: work(fd, bag), rng.uniform(0.0, LATE * lifetime))
        flushed = max([int(f[1]) for f in lines if f[0] == "F"], default=0)
        flushed_total += flushed
        if not bag.exists():
            if flushed:
                faults.append(f"kill {k}: no bag after {flushed} messages flushed")
            continue
        split_files += len(list(bag.glob("*.mcap")))
        try:
            table = read_passes(bag)
            strict += 1
        except RailMonitorError as exc:
            if "\n" in str(exc):
                faults.append(f"kill {k}: refused in more than one line: {exc!r}")
            try:
                table, _ = salvage_bag_passes(bag)
            except RailMonitorError as exc2:
                if flushed:
                    faults.append(f"kill {k}: {flushed} flushed, nothing salvaged: {exc2}")
                table = PassTable.empty()
        n = len(table)
        salvaged_total += n
        if n < flushed:
            faults.append(f"kill {k}: {flushed} messages reported flushed, {n} recovered")
        if n and pass_cdr(table, "kill_harness") != cdr[:n]:
            faults.append(f"kill {k}: the {n} messages recovered are not the first {n} written")
        shutil.rmtree(bag)
    return {"kills": kills, "faults": faults, "life_s": lifetime, "read_strictly": strict, "flushed": flushed_total,
            "recovered": salvaged_total, "files": split_files}


if __name__ == "__main__":
    mode, kills, seed, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), Path(sys.argv[4])
    out.mkdir(parents=True, exist_ok=True)
    print(json.dumps((checkpoints if mode == "checkpoint" else recordings)(kills, seed, out)))
