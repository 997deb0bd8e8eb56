"""What the rolling noise prediction takes of a corrugation state and what it gives per pass."""

from __future__ import annotations

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
        pairs = [(c, float(x)) for c, x in zip(self.component_names, self.component_lpaeq_dba[i], strict=True)
                 if x > -np.inf]
        return [c for c, _ in pairs], [x for _, x in pairs]

    def per_pass(self) -> dict[str, np.ndarray]:
        """The arrays over passes, by field name."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name not in self.CONSTANTS}

    @classmethod
    def concat(cls, parts: Sequence[NoisePrediction]) -> NoisePrediction:
        """The passes of parts (same model and bands), one after the other."""
        return replace(parts[0], **{k: np.concatenate([p.per_pass()[k] for p in parts])
                                    for k in parts[0].per_pass()})

    def merged(self, mask: np.ndarray, other: NoisePrediction) -> NoisePrediction:
        """These rows where mask is true and other's where it is false, in pass order."""
        out = {}
        for k, mine in self.per_pass().items():
            col = np.empty((len(mask), *mine.shape[1:]), mine.dtype)
            col[mask], col[~mask] = mine, other.per_pass()[k]
            out[k] = col
        return replace(self, **out)
