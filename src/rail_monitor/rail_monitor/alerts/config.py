"""The site's alert parameters (thresholds, windows, hysteresis) and the alert kinds and severities."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, resolve, section, values_of

# WaysideAlert.KIND_* and SEVERITY_* values.
(KIND_GRINDING_DUE, KIND_GRINDING_FORECAST, KIND_NOISE_LIMIT, KIND_SQUEAL, KIND_INPUT_REJECTED, KIND_WHEEL_DEFECT,
 KIND_NOISE_DRIFT, KIND_SQUEAL_MISMATCH, KIND_SQUEAL_MEASURED, KIND_SQUEAL_OFFENDER, KIND_SQUEAL_DRIFT) = range(1, 12)
KIND_NAMES = {KIND_GRINDING_DUE: "grinding due", KIND_GRINDING_FORECAST: "grinding forecast",
              KIND_NOISE_LIMIT: "noise limit", KIND_SQUEAL: "squeal", KIND_INPUT_REJECTED: "inputs rejected",
              KIND_WHEEL_DEFECT: "wheel defect", KIND_NOISE_DRIFT: "noise drift",
              KIND_SQUEAL_MISMATCH: "squeal mismatch", KIND_SQUEAL_MEASURED: "squeal measured",
              KIND_SQUEAL_OFFENDER: "repeat squealer", KIND_SQUEAL_DRIFT: "squeal model drift"}
SEVERITY_INFO, SEVERITY_WARNING, SEVERITY_CRITICAL = range(3)
NOISE_METRICS = ("lpaeq_tp_dba", "lpafmax_dba", "tel_dba")  # RollingNoise single numbers
RISK_NAMES = ("none", "low", "medium", "high")


def counts_as_squeal(risk: np.ndarray, min_risk: str) -> np.ndarray:
    """Whether each squeal risk (RISK_* number, or its name) counts as an occurrence: at or above
    the site's ``squeal_min_risk`` (the alert's rule, and the report's)."""
    risk = np.asarray(risk)
    if risk.dtype.kind in "OUS":
        risk = np.array([RISK_NAMES.index(r) if r in RISK_NAMES else -1 for r in risk.tolist()], dtype=np.int64)
    return risk >= RISK_NAMES.index(min_risk)

ALERT_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("grinding_clear_fraction", 0.9, "A grinding-due alert clears below this fraction of the band's "
              "threshold [-].", 0.01, 1.0),
    ParamSpec("forecast_clear_factor", 1.2, "A grinding-forecast alert clears when the forecast is beyond this "
              "multiple of the lead time [-].", 1.0, 100.0),
    ParamSpec("noise_metric", "lpafmax_dba", "Pass-by level compared with the limit.", choices=NOISE_METRICS),
    ParamSpec("noise_limit_dba", 88.0, "Pass-by noise limit at the receiver [dB(A)].", 0.0, 200.0),
    ParamSpec("noise_hysteresis_db", 3.0, "A pass counts towards clearing only below the limit minus this [dB].",
              0.0, 60.0),
    ParamSpec("noise_window_passes", 20, "Passes over which noise exceedances are counted [-].", 1, 100_000),
    ParamSpec("noise_raise_count", 1, "Exceedances in the window that raise the alert [-].", 1, 100_000),
    ParamSpec("noise_clear_count", 0, "Exceedances in the window at or below which it clears [-].", 0, 100_000),
    ParamSpec("squeal_min_risk", "medium", "Squeal risk that counts as an occurrence.", choices=RISK_NAMES[1:]),
    ParamSpec("squeal_window_passes", 200, "Passes over which squeal occurrences are counted [-].", 1, 100_000),
    ParamSpec("squeal_raise_share", 0.2, "Share of squealing passes in the window that raises the alert [-].",
              0.0, 1.0),
    ParamSpec("squeal_clear_share", 0.125, "Share at or below which it clears [-].", 0.0, 1.0),
    ParamSpec("rejected_window_passes", 100, "TrainPass messages over which rejections are counted [-].",
              1, 100_000),
    ParamSpec("rejected_raise_share", 0.05, "Share of rejected messages that raises the alert [-].", 0.0, 1.0),
    ParamSpec("rejected_clear_share", 0.0, "Share at or below which it clears [-].", 0.0, 1.0),
    ParamSpec("residual_model", "cnossos", "Source model whose measured-minus-predicted residuals the wheel-defect "
              "and drift alerts use.", choices=("cnossos", "mechanics")),
    ParamSpec("wheel_defect_raise_db", 6.0, "A pass this far above the site's baseline residual at 500-2000 Hz "
              "raises a wheel-defect alert for its loudest vehicle (or the train) [dB].", 0.5, 60.0),
    ParamSpec("wheel_defect_clear_db", 3.0, "A later pass of that vehicle (or train) below this clears it [dB].",
              0.0, 60.0),
    ParamSpec("wheel_defect_vehicle_db", 2.0, "The loudest vehicle segment is named when this far above the "
              "train's mean (else the train) [dB].", 0.0, 60.0),
    ParamSpec("drift_raise_db", 3.0, "The baseline residual's rise since it was first full that raises the drift "
              "alert [dB].", 0.1, 60.0),
    ParamSpec("drift_clear_db", 1.5, "The rise below which it clears [dB].", 0.0, 60.0),
    ParamSpec("squeal_mismatch_window_passes", 100, "Measured passes over which squeal measured but not "
              "predicted (at squeal_min_risk), and the reverse, are counted [-].", 1, 100_000),
    ParamSpec("squeal_mismatch_raise_share", 0.2, "Share of the window's measured passes that raises either "
              "mismatch alert [-].", 0.0, 1.0),
    ParamSpec("squeal_mismatch_clear_share", 0.1, "Share at or below which it clears [-].", 0.0, 1.0),
    ParamSpec("squeal_measured_window_passes", 200, "Measured passes over which the station's squeal flags are "
              "counted [-].", 1, 100_000),
    ParamSpec("squeal_measured_raise_share", 0.2, "Share of the window's measured passes flagged squealing that "
              "raises the measured-squeal alert (the site's limit) [-].", 0.0, 1.0),
    ParamSpec("squeal_measured_clear_share", 0.125, "Share at or below which it clears [-].", 0.0, 1.0),
    ParamSpec("squeal_offender_window_passes", 50, "A vehicle's (or train's) last measured passes over which its "
              "squeal is weighed [-].", 1, 100_000),
    ParamSpec("squeal_offender_min_passes", 10, "Measured passes a vehicle (or train) needs before it may be "
              "named a repeat squealer [-].", 1, 100_000),
    ParamSpec("squeal_offender_raise_p", 1e-5, "A vehicle is named when the chance of squealing that often, at "
              "the site's measured share for passes of the same predicted risk, falls below this [-].", 1e-15, 0.5),
    ParamSpec("squeal_offender_clear_p", 0.01, "It is cleared when that chance rises above this [-].", 1e-15, 1.0),
    ParamSpec("squeal_drift_windows", 3, "Squeal fits running whose window's measured squeal share of a friction "
              "state lies outside the share the model predicted for it (P10-P90), on one side, that raise the "
              "state's model-drift alert (a window inside clears it) [-].", 1, 1000),
    ParamSpec("squeal_drift_min_passes", 30, "Measured passes of a state a fit window needs to be judged [-].",
              1, 100_000),
)
# Every alert parameter may be changed on a running alert_manager (ros2 param set): an operator
# tunes limits and windows without a restart; the same checks refuse a bad value with the reason.
ALERT_SPECS = tuple(replace(s, tunable=True) for s in ALERT_SPECS)


@dataclass(frozen=True)
class AlertConfig:
    """The site's alert parameters (names and units as in ALERT_SPECS), with the corrugation lead time [day]."""

    grinding_clear_fraction: float
    forecast_clear_factor: float
    noise_metric: str
    noise_limit_dba: float
    noise_hysteresis_db: float
    noise_window_passes: int
    noise_raise_count: int
    noise_clear_count: int
    squeal_min_risk: str
    squeal_window_passes: int
    squeal_raise_share: float
    squeal_clear_share: float
    rejected_window_passes: int
    rejected_raise_share: float
    rejected_clear_share: float
    residual_model: str
    wheel_defect_raise_db: float
    wheel_defect_clear_db: float
    wheel_defect_vehicle_db: float
    drift_raise_db: float
    drift_clear_db: float
    squeal_mismatch_window_passes: int
    squeal_mismatch_raise_share: float
    squeal_mismatch_clear_share: float
    squeal_measured_window_passes: int
    squeal_measured_raise_share: float
    squeal_measured_clear_share: float
    squeal_offender_window_passes: int
    squeal_offender_min_passes: int
    squeal_offender_raise_p: float
    squeal_offender_clear_p: float
    squeal_drift_windows: int
    squeal_drift_min_passes: int
    lead_time_days: float


def alert_config(values: Mapping[str, Any], lead_time_days: float, prefix: str = "alerts.") -> AlertConfig:
    """Checked alert parameters from flat values (keys under prefix); ConfigError without hysteresis."""
    out = resolve(ALERT_SPECS, section(values, prefix), where=prefix, strict=True)
    for name, raise_key, clear_key in (("noise", "noise_raise_count", "noise_clear_count"),
                                       ("squeal", "squeal_raise_share", "squeal_clear_share"),
                                       ("rejected", "rejected_raise_share", "rejected_clear_share"),
                                       ("wheel defect", "wheel_defect_raise_db", "wheel_defect_clear_db"),
                                       ("drift", "drift_raise_db", "drift_clear_db"),
                                       ("squeal mismatch", "squeal_mismatch_raise_share",
                                        "squeal_mismatch_clear_share"),
                                       ("measured squeal", "squeal_measured_raise_share",
                                        "squeal_measured_clear_share")):
        if out[clear_key] >= out[raise_key]:
            raise ConfigError(f"parameter '{prefix}{clear_key}' must be below '{prefix}{raise_key}' "
                              f"(the {name} alert needs hysteresis)")
    if out["squeal_offender_clear_p"] <= out["squeal_offender_raise_p"]:
        raise ConfigError(f"parameter '{prefix}squeal_offender_clear_p' must be above "
                          f"'{prefix}squeal_offender_raise_p' (the repeat-squealer alert needs hysteresis)")
    if out["noise_raise_count"] > out["noise_window_passes"]:
        raise ConfigError(f"parameter '{prefix}noise_raise_count' exceeds '{prefix}noise_window_passes'")
    out["lead_time_days"] = float(lead_time_days)
    return values_of(AlertConfig, out)
