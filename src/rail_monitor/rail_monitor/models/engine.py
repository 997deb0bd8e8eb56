"""The engines that evaluate the models' heaviest loops: ``numpy`` (every process; the live
nodes) and ``numba`` (the same arithmetic compiled, for batch mode: models.passby_axles_jit,
models.corrugation_jit)."""

from __future__ import annotations

from types import ModuleType

ENGINES = ("numpy", "numba")


def check_engine(engine: str) -> str:
    """engine, or a ValueError naming the known ones."""
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}: one of {ENGINES}")
    return engine


def corrugation_kernels(engine: str) -> ModuleType:
    """The module of the corrugation state's array kernels (band_log_amplitude,
    passes_to_band_level, first_band_to_level, table_growth, history_sums, window_growth, add_by_day) of an
    engine."""
    if check_engine(engine) == "numba":
        from rail_monitor.models import corrugation_jit

        return corrugation_jit
    from rail_monitor.models import corrugation_state

    return corrugation_state
