"""The rolling noise of a chunk of passes, each on the corrugation state that includes it, as
tasks of a thread pool over bounded sub-chunks (no rclpy)."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor, Future, ThreadPoolExecutor
from typing import Any

import numpy as np

from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.records import StateSnapshot
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.noise.records import Corrugation, NoiseRows

NOISE_CHUNK = 8_192  # passes per noise prediction (every model): bounds its (passes x bands) arrays


class InThisThread(Executor):
    """An executor that runs each task at once in the caller's thread: one thread's worth of
    work without starting a pool (a live pass costs less than a thread's start)."""

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        done: Future = Future()
        try:
            done.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # handed to the caller through result(), as a pool does
            done.set_exception(exc)
        return done


def pool_of(threads: int) -> Executor:
    """A thread pool of ``threads`` workers, or the caller's thread for one."""
    return ThreadPoolExecutor(max_workers=threads) if threads > 1 else InThisThread()


def noise_on_states(pool: Executor, model: RollingNoiseModel, accepted: PassTable,
                     amplitude: np.ndarray, constants: StateSnapshot, state_of_pass: np.ndarray, out: NoiseRows,
                     first_row: int) -> list[Future]:
    """Every model's noise of every accepted pass, each on its state (row of amplitude; -1: passes
    before any state, on none), as tasks of pool that put their rows into out (the passes being
    its rows from first_row on)."""
    have = state_of_pass >= 0
    state = Corrugation(constants.bands, amplitude[state_of_pass[have]], constants.grinding_amplitude)
    jobs = noise_chunks(pool, model, accepted.take(have), out, first_row + np.flatnonzero(have), state)
    return jobs if have.all() else jobs + noise_chunks(pool, model, accepted.take(~have), out,
                                                        first_row + np.flatnonzero(~have))


def noise_chunks(pool: Executor, model: RollingNoiseModel, passes: PassTable, out: NoiseRows,
                  rows: np.ndarray, corrugation: Corrugation | None = None) -> list[Future]:
    """model.predict_models over chunks of NOISE_CHUNK passes (each independent), a task each putting
    their predictions at rows of out; in class order, so the model reads a class's rows as a slice."""
    order = passes.class_order()
    passes, rows = passes.take(order), rows[order]
    corrugation = None if corrugation is None else corrugation.of_passes(order)

    def task(part: slice, state: Corrugation | None) -> None:
        out.put(rows[part], model.predict_models(passes.take(part), (), state))

    jobs = []
    for i in range(0, max(len(passes), 1), NOISE_CHUNK):
        part = slice(i, i + NOISE_CHUNK)
        jobs.append(pool.submit(task, part, None if corrugation is None else corrugation.of_passes(part)))
    return jobs
