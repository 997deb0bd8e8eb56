"""What the corrugation state reports: forecasts, snapshots, trajectories over a history, what-if
evaluations and speed advice (units as in rail_msgs/CorrugationState and SpeedAdvisory)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np


@dataclass
class Forecast:
    """The grinding forecast of a state (units as in rail_msgs/CorrugationState)."""

    growth_per_axle_pass: np.ndarray   # per band: its fastest component's [1/axle pass]
    worst_band: int
    passes_to_threshold: float
    days_to_threshold: float
    passes_per_day: float
    grinding_due: bool
    grinding_due_ns: int            # 0: never


@dataclass(frozen=True)
class ForecastInterval:
    """The grinding forecast's P10, P50 and P90: days to threshold per band (3, B), of the first
    band to reach it (3,), and that date (3,) [ns] (0: never, or past the dated horizon)."""

    band_days: np.ndarray
    days: np.ndarray
    due_ns: np.ndarray
    basis: str = "recent"          # the traffic forecast: "recent" window, or "season" a year earlier


@dataclass(frozen=True)
class StateSnapshot:
    """What a CorrugationState carries besides the forecast (units as in the message)."""

    newest_ns: int
    newest_train_id: str
    pass_count: int
    axle_pass_count: int
    total_pass_count: int
    last_grinding_ns: int
    bands: np.ndarray
    amplitude: np.ndarray
    threshold: np.ndarray
    grinding_amplitude: np.ndarray
    k_b: np.ndarray
    k_b_p10: np.ndarray
    k_b_p90: np.ndarray
    calibration_surveys: int


@dataclass
class Trajectory:
    """The state after each counted pass of a history (batch mode): arrays over counted passes.

    index: row of each counted pass in the history given; constants: the snapshot before the
    history (bands, thresholds, post-grinding amplitudes, K_b, last grinding); constants_from:
    (first counted pass, snapshot) where a survey or grinding changed them within the history.
    """

    index: np.ndarray
    stamp_ns: np.ndarray
    train_id: np.ndarray
    amplitude: np.ndarray          # (M, B) [m]
    pass_count: np.ndarray
    axle_pass_count: np.ndarray
    total_pass_count: np.ndarray
    forecast: Forecast             # of arrays (M,) and (M, B)
    constants: StateSnapshot
    constants_from: tuple[tuple[int, StateSnapshot], ...] = ()

    def __len__(self) -> int:
        return len(self.index)

    def state(self, k: int) -> tuple[StateSnapshot, Forecast]:
        """The snapshot and forecast after counted pass k (for message conversion)."""
        c, f = self.constants_at(k), self.forecast
        snap = StateSnapshot(int(self.stamp_ns[k]), str(self.train_id[k]), int(self.pass_count[k]),
                             int(self.axle_pass_count[k]), int(self.total_pass_count[k]), c.last_grinding_ns,
                             c.bands, self.amplitude[k], c.threshold, c.grinding_amplitude, c.k_b,
                             c.k_b_p10, c.k_b_p90, c.calibration_surveys)
        return snap, Forecast(f.growth_per_axle_pass[k], int(f.worst_band[k]), float(f.passes_to_threshold[k]),
                              float(f.days_to_threshold[k]), float(f.passes_per_day[k]), bool(f.grinding_due[k]),
                              int(f.grinding_due_ns[k]))

    def constants_at(self, k: int) -> StateSnapshot:
        """The constants in force at counted pass k."""
        c = self.constants
        for first, later in self.constants_from:
            if first > k:
                break
            c = later
        return c

    @classmethod
    def from_rows(cls, rows: list[tuple[int, StateSnapshot, Forecast]], last: StateSnapshot) -> Trajectory:
        """From (history row, snapshot, forecast) per counted pass, taken one by one."""
        def col(get, dtype=float) -> np.ndarray:
            return np.array([get(s, f) for _, s, f in rows], dtype=dtype)

        nb = len(last.bands)
        fc = Forecast(col(lambda s, f: f.growth_per_axle_pass).reshape(-1, nb), col(lambda s, f: f.worst_band, int),
                      col(lambda s, f: f.passes_to_threshold), col(lambda s, f: f.days_to_threshold),
                      col(lambda s, f: f.passes_per_day), col(lambda s, f: f.grinding_due, bool),
                      col(lambda s, f: f.grinding_due_ns, np.int64))
        return cls(np.array([i for i, _, _ in rows], np.int64), col(lambda s, f: s.newest_ns, np.int64),
                   col(lambda s, f: s.newest_train_id, object), col(lambda s, f: s.amplitude).reshape(-1, nb),
                   col(lambda s, f: s.pass_count, np.int64), col(lambda s, f: s.axle_pass_count, np.int64),
                   col(lambda s, f: s.total_pass_count, np.int64), fc, last)

    @classmethod
    def concat(cls, parts: Sequence[tuple[int, Trajectory]]) -> Trajectory:
        """Trajectories of consecutive chunks of one history, each with the history row its chunk
        starts at, as one (constants: the first chunk's, the state before the history; each later
        chunk's from its first counted pass)."""
        first = parts[0][1]
        offsets = np.cumsum([0, *(len(t) for _, t in parts)]).tolist()
        changes: list[tuple[int, StateSnapshot]] = []
        for i, (_, t) in enumerate(parts):
            changes += [(offsets[i], t.constants)] if i else []
            changes += [(offsets[i] + k, c) for k, c in t.constants_from]

        def join(get) -> np.ndarray:
            return np.concatenate([get(t) for _, t in parts])

        fc = Forecast(**{f.name: join(lambda t, k=f.name: getattr(t.forecast, k)) for f in fields(Forecast)})
        per_pass = {f.name: join(lambda t, k=f.name: getattr(t, k)) for f in fields(cls)
                    if f.name not in ("index", "forecast", "constants", "constants_from")}
        return cls(index=np.concatenate([t.index + start for start, t in parts]), forecast=fc,
                   constants=first.constants, constants_from=tuple(changes), **per_pass)


@dataclass
class Evaluation:
    """A speed distribution's growth against the state (units as in EvaluateSpeedDistribution)."""

    growth_per_axle_pass: np.ndarray
    peak_growth: float
    peak_wavelength_m: float
    grinding_interval_factor: float
    days_to_threshold: float
