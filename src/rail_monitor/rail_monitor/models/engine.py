"""The engines that evaluate the models' heaviest loops: ``numpy`` (every process; the live
nodes) and ``numba`` (the same arithmetic compiled, for batch mode: models.passby_axles_jit,
models.corrugation_jit)."""

from __future__ import annotations

ENGINES = ("numpy", "numba")


def check_engine(engine: str) -> str:
    """engine, or a ValueError naming the known ones."""
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}: one of {ENGINES}")
    return engine
