"""A recorded run read back as arrays (no rclpy): what the graph (or batch mode) recorded,
train_pass, noise/squeal, corrugation/state, noise/rolling, alerts, speed_advisory, measured
pass-bys and residuals, matched by message type, so any namespace works; whole
(:func:`load_run`) or in stamp-ordered parts (:func:`iter_runs`)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor.alerts.manager import Alert
from rail_monitor.bagio.reader import iter_messages, read_messages
from rail_monitor.core.errors import InputError, RailMonitorError
from rail_monitor.core.friction import ApplicatorEvent, applicator_refusal
from rail_monitor.core.passes import PassTable
from rail_monitor.measured.records import SQUEAL_MEASURES
from rail_monitor.messages.event_fields import applicator_from_msg
from rail_monitor.messages.fields import alert_from_msg, pass_row, time_ns

_TYPES = ("TrainPass", "SquealPrediction", "CorrugationState", "RollingNoise", "WaysideAlert", "SpeedAdvisory",
          "MeasuredPassNoise", "NoiseResidual", "SquealCalibration", "FrictionApplicator")
_FIT = ("k1_configured", "k2_configured", "k1_p10", "k1_p50", "k1_p90", "k2_p10", "k2_p50", "k2_p90",
        "measured_passes", "squealing_passes")
_FIT_WINDOW = ("window_passes", "window_squealing", "window_share_p10", "window_share_p50", "window_share_p90")
_MEASURED = ("lpaeq_tp_dba", "lpafmax_dba", "tel_dba", "squeal_detected", "instrument_class", *SQUEAL_MEASURES)
_RESIDUAL = ("residual_lpaeq_dba", "residual_lpafmax_dba", "residual_tel_dba", "residual_mid_db", "baseline_mid_db",
             "drift_db", "excess_mid_db", "loudest_vehicle_id", "loudest_vehicle_excess_db")
_STATE = ("amplitude_m", "threshold_m", "post_grinding_m", "growth_per_axle_pass")
_STATE_NUMBERS = ("days_to_threshold", "passes_to_threshold", "passes_per_day", "worst_band", "pass_count",
                  "axle_pass_count", "total_pass_count")


@dataclass
class RunData:
    """The recorded outputs of one run, as arrays (units as in the messages)."""

    bag: Path
    passes: PassTable
    squeal: dict[str, np.ndarray] = field(default_factory=dict)
    states: dict[str, np.ndarray] = field(default_factory=dict)
    noise: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    alerts: list[Alert] = field(default_factory=list)
    advisory: Any = None
    measured: dict[str, np.ndarray] = field(default_factory=dict)               # MeasuredPassNoise fields
    residuals: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)   # NoiseResidual fields, by model
    squeal_fits: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)  # SquealCalibration, by state
    applicator: list[ApplicatorEvent] = field(default_factory=list)  # FrictionApplicator, in stamp order


def load_run(bag: str | Path) -> RunData:
    """Everything the report needs from a bag (InputError with one line if it cannot be read)."""
    path = Path(bag)
    run = _run_of(path, read_messages(path, [f"rail_msgs/msg/{n}" for n in _TYPES]))
    if not len(run.passes):
        raise InputError(f"{path}: no rail_msgs/msg/TrainPass messages: nothing to report")
    return run


class NotStampOrdered(RailMonitorError):
    """A bag whose log times are not its messages' header stamps (not recorded by rail_monitor)."""


def iter_runs(bag: str | Path, chunk: int = 5_000) -> Iterator[RunData]:
    """A bag's run as consecutive RunData of about ``chunk`` passes each, in time order, for a
    bag rail_monitor recorded (log time = header stamp, so a pass's outputs share its log time):
    each part holds its passes, their outputs, the state before its first pass (the one its first
    passes are reported on) and the alert events of its time; the last part the speed advisory.
    Memory: one part. NotStampOrdered (before any part of that time is given) for another bag."""
    path = Path(bag)
    held: list[tuple[str, int, Any]] = []
    passes, cut, before, any_pass = 0, None, None, False
    for part in iter_messages(path, [f"rail_msgs/msg/{n}" for n in _TYPES], chunk):
        for item in part:
            typename, t, msg = item
            if t != max(time_ns(msg.header.stamp), 0):
                raise NotStampOrdered(f"{path}: a {typename} is logged at {t} ns, not at its stamp: not a bag "
                                      "rail_monitor recorded")
            if cut is not None and t > cut:
                run, before = _part(path, held, before)
                yield run
                held, passes, cut = [], 0, None
            held.append(item)
            if typename.endswith("/TrainPass"):
                passes += 1
                any_pass = True
                if passes >= chunk:
                    cut = t
    if not any_pass:
        raise InputError(f"{path}: no rail_msgs/msg/TrainPass messages: nothing to report")
    yield _part(path, held, before)[0]


def _part(path: Path, items: list[tuple[str, int, Any]], before: Any) -> tuple[RunData, Any]:
    """The RunData of a part's messages with the state before it; and the state after it."""
    got: dict[str, list[Any]] = {f"rail_msgs/msg/{n}": [] for n in _TYPES}
    for typename, _, msg in items:
        got[typename].append(msg)
    states = got["rail_msgs/msg/CorrugationState"]
    after = states[-1] if states else before
    if before is not None:
        states.insert(0, before)
    return _run_of(path, got), after


def _run_of(path: Path, got: dict[str, list[Any]]) -> RunData:
    """RunData of a bag's messages by type."""
    rows = [pass_row(m) for m in got["rail_msgs/msg/TrainPass"]]
    sq, st, nz, al = (got[f"rail_msgs/msg/{n}"] for n in ("SquealPrediction", "CorrugationState", "RollingNoise",
                                                           "WaysideAlert"))
    advisories = got["rail_msgs/msg/SpeedAdvisory"]
    run = RunData(path, PassTable.from_rows(rows))
    run.squeal = {k: np.array([getattr(m, k) for m in sq]) for k in (
        "crabbing_velocity_mps", "velocity_amplitude_mps", "risk", "level_dba", "friction_state", "speed_mps",
        "regime", "unstable", "frequency_hz", "friction_modifier_benefit_db")}
    run.squeal["train_id"] = np.array([m.train_id for m in sq], object)
    run.squeal["stamp_ns"] = np.array([time_ns(m.header.stamp) for m in sq], np.int64)
    if st:
        run.states = {k: np.array([list(getattr(m, k)) for m in st]) for k in _STATE}
        run.states.update({k: np.array([getattr(m, k) for m in st]) for k in _STATE_NUMBERS})
        run.states["wavelength_m"] = np.array(st[-1].wavelength_m)
        for k in ("stamp", "last_grinding_time", "grinding_due_time"):
            run.states[k] = np.array([time_ns(getattr(m, k) if k != "stamp" else m.header.stamp) for m in st], np.int64)
        run.states["grinding_due"] = np.array([m.grinding_due for m in st])
    for model in sorted({m.model for m in nz}):
        ms = [m for m in nz if m.model == model]
        run.noise[model] = {k: np.array([getattr(m, k) for m in ms]) for k in (
            "lpaeq_tp_dba", "lpafmax_dba", "tel_dba", "speed_mps", "roughness_growth_increase_db")}
        run.noise[model]["stamp_ns"] = np.array([time_ns(m.header.stamp) for m in ms], np.int64)
        run.noise[model]["train_id"] = np.array([m.train_id for m in ms], object)
        run.noise[model]["lp_db"] = np.array([list(m.lp_db) for m in ms])
        run.noise[model]["band_centre_hz"] = np.array(ms[0].band_centre_hz)
    measured = got["rail_msgs/msg/MeasuredPassNoise"]
    if measured:
        run.measured = _columns(measured, _MEASURED)
    for model in sorted({m.model for m in got["rail_msgs/msg/NoiseResidual"]}):
        run.residuals[model] = _columns([m for m in got["rail_msgs/msg/NoiseResidual"] if m.model == model],
                                        _RESIDUAL)
    for msg in got["rail_msgs/msg/SquealCalibration"]:  # one row per fit of each state
        for i, state in enumerate(msg.friction_state):
            fit = run.squeal_fits.setdefault(state, {"stamp_ns": [], **{k: [] for k in _FIT + _FIT_WINDOW}})
            fit["stamp_ns"].append(time_ns(msg.header.stamp))
            for k in _FIT:
                fit[k].append(getattr(msg, k)[i])
            for k in _FIT_WINDOW:  # a bag of 0.26.0 has no windows: NaN
                fit[k].append(getattr(msg, k)[i] if len(getattr(msg, k, ())) > i else np.nan)
    run.squeal_fits = {s: {k: np.array(v) for k, v in f.items()} for s, f in run.squeal_fits.items()}
    events = (applicator_from_msg(m) for m in got["rail_msgs/msg/FrictionApplicator"])
    run.applicator = sorted((e for e in events if not applicator_refusal(e)), key=lambda e: e.stamp_ns)
    run.alerts = sorted((alert_from_msg(m) for m in al), key=lambda a: (a.stamp_ns, a.kind, a.key, a.active))
    run.advisory = advisories[-1] if advisories else None
    return run


def _columns(msgs: list[Any], names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """Fields of messages as arrays, with their stamps [ns] and train ids."""
    # A bag recorded before the squeal measures (0.23 and earlier): not measured.
    out = {k: np.array([getattr(m, k, SQUEAL_MEASURES.get(k)) for m in msgs]) for k in names}
    out["stamp_ns"] = np.array([time_ns(m.header.stamp) for m in msgs], np.int64)
    out["train_id"] = np.array([m.train_id for m in msgs], object)
    return out


# -- summary ------------------------------------------------------------------------------------
