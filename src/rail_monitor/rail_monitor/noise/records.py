"""What the rolling noise prediction takes of a corrugation state and what it gives per pass."""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace

import numpy as np


@dataclass(frozen=True)
class Corrugation:
    """The part of a CorrugationState the noise needs: bands [m] and r.m.s. amplitudes [m].

    amplitude_m and post_grinding_m are (bands,) for one state, or (passes, bands) for a state per
    pass (batch mode)."""

    wavelength_m: np.ndarray
    amplitude_m: np.ndarray
    post_grinding_m: np.ndarray

    def of_passes(self, index: np.ndarray | slice) -> Corrugation:
        """The state of the passes at index: a state per pass taken at those rows, one state kept."""
        if self.amplitude_m.ndim == 1:
            return self
        return replace(self, amplitude_m=self.amplitude_m[index])


@dataclass(frozen=True)
class NoisePrediction:
    """Rolling noise of passes by one source model (fields and units as in rail_msgs/RollingNoise):
    the model, band centres and component names, then arrays over passes (bands last)."""

    model: str
    band_centre_hz: np.ndarray              # (B,) [Hz]
    component_names: list[str]
    speed_mps: np.ndarray                   # (N,) [m/s]
    lp_db: np.ndarray                       # (N, B) LpZeq,Tp per band [dB re 20 uPa]
    lw_db: np.ndarray                       # (N, B) sound power per metre of train [dB re 1 pW/m]
    roughness_db: np.ndarray                # (N, B) effective roughness [dB re 1 um]
    pass_by_time_s: np.ndarray              # (N,) [s]
    lpaeq_tp_dba: np.ndarray                # (N,) [dB(A)]
    lpafmax_dba: np.ndarray                 # (N,) [dB(A)]
    tel_dba: np.ndarray                     # (N,) [dB(A)]
    component_lpaeq_dba: np.ndarray         # (N, components) [dB(A)]
    roughness_growth_increase_db: np.ndarray  # (N,) [dB]

    CONSTANTS = ("model", "band_centre_hz", "component_names")

    def __len__(self) -> int:
        return len(self.speed_mps)

    def components(self, i: int) -> tuple[list[str], list[float]]:
        """Pass i's source components and their LpAeq,Tp [dB(A)]: those its class has (the
        superstructure term is for freight only), in component_names order."""
        levels = self.component_lpaeq_dba[i]
        has = _present(levels)
        return [c for c, h in zip(self.component_names, has.tolist(), strict=True) if h], levels[has].tolist()

    def components_of_all(self) -> tuple[list[list[str]], np.ndarray | list[np.ndarray]]:
        """components(i) of every pass: the names per pass, and the levels as one (N, C) array
        where every pass has the same components, else one array per pass."""
        has = _present(self.component_lpaeq_dba)
        patterns, inverse = np.unique(has, axis=0, return_inverse=True)
        inverse = inverse.reshape(-1)
        names = [[c for c, h in zip(self.component_names, pattern, strict=True) if h] for pattern in patterns.tolist()]
        if len(patterns) == 1:
            return [names[0]] * len(self), self.component_lpaeq_dba[:, patterns[0]]
        values: list[np.ndarray] = [np.empty(0)] * len(self)
        for k, pattern in enumerate(patterns):
            rows = np.flatnonzero(inverse == k)
            for i, row in zip(rows.tolist(), self.component_lpaeq_dba[np.ix_(rows, pattern)], strict=True):
                values[i] = row
        return [names[k] for k in inverse.tolist()], values

    def per_pass(self) -> dict[str, np.ndarray]:
        """The arrays over passes, by field name."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name not in self.CONSTANTS}

    @classmethod
    def concat(cls, parts: Sequence[NoisePrediction]) -> NoisePrediction:
        """The passes of parts (same model and bands), one after the other."""
        return replace(parts[0], **{k: np.concatenate([p.per_pass()[k] for p in parts])
                                    for k in parts[0].per_pass()})



def _present(levels: np.ndarray) -> np.ndarray:
    """Which source components a pass has: a component its class does not have is at -inf dB(A)."""
    return levels > -np.inf


class NoiseRows:
    """Every model's predictions of n passes, filled part by part from any thread (batch mode's
    noise tasks write their rows as they finish, so no part is copied again at the end)."""

    def __init__(self, n: int) -> None:
        self.n = n
        self._columns: dict[str, NoisePrediction] = {}
        self._lock = threading.Lock()

    def put(self, rows: np.ndarray | slice, predictions: dict[str, NoisePrediction]) -> None:
        """The predictions of the passes at rows (an index array or a slice of the n)."""
        if not isinstance(rows, slice) and len(rows) and rows[-1] - rows[0] == len(rows) - 1 \
                and (np.diff(rows) == 1).all():
            rows = slice(int(rows[0]), int(rows[-1]) + 1)  # ascending and contiguous: a block copy
        for name, p in predictions.items():
            with self._lock:  # the first part of a model sets its columns' shapes
                if name not in self._columns:
                    self._columns[name] = replace(p, **{k: np.empty((self.n, *v.shape[1:]), v.dtype)
                                                        for k, v in p.per_pass().items()})
            column = self._columns[name].per_pass()
            for k, v in p.per_pass().items():
                column[k][rows] = v

    def predictions(self) -> dict[str, NoisePrediction]:
        """By model, once every row is put."""
        return dict(self._columns)
