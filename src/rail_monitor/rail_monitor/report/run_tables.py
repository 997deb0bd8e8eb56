"""Tables of a recorded run: one row per pass with every model output, and one row per alert event
(what rail_monitor.report.export writes and the report computes from).

Outputs are joined to their pass by (train_id, pass stamp), as the graph stamps every output with
its pass's time. The corrugation columns are the state after the pass: the newest state recorded
at or before the pass time. Units are in the column names (as in the pass CSV).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.alerts.config import KIND_NAMES, RISK_NAMES
from rail_monitor.core.passes import FRICTION_NAMES, KMH_PER_MPS, rejection_reasons
from rail_monitor.core.timeutil import format_iso_ns, format_local_ns
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.models.squeal import REGIME_NAMES
from rail_monitor.noise.predict import INCREASE_REFERENCE
from rail_monitor.report.run_data import RunData

SEVERITY_NAMES = ("info", "warning", "critical")


@dataclass(frozen=True)
class Column:
    name: str
    unit: str
    description: str
    values: np.ndarray


@dataclass(frozen=True)
class Table:
    name: str
    columns: list[Column]

    def as_dict(self) -> dict[str, np.ndarray]:
        return {c.name: c.values for c in self.columns}


def _lookup(keys: list[tuple[str, int]], of: list[tuple[str, int]]) -> np.ndarray:
    """Index into `of` of each key (-1 where a pass has no such output)."""
    where = {k: i for i, k in enumerate(of)}
    return np.array([where.get(k, -1) for k in keys], np.int64)


def _pick(values: np.ndarray, index: np.ndarray, fill: Any = np.nan) -> np.ndarray:
    """values[index], fill where index is -1 (float columns get NaN there, and for a non-finite value:
    'none' or 'never', an empty cell), others the fill."""
    values = np.asarray(values)
    numeric = values.dtype.kind in "fc"
    if numeric:
        values = np.where(np.isfinite(values), values, np.nan)
    out = np.full(len(index), np.nan) if numeric else np.full(len(index), fill, dtype=object)
    ok = index >= 0
    out[ok] = values[index[ok]]
    return out


def pass_table(run: RunData, cfg: SiteConfig) -> Table:
    """One row per recorded pass: the pass, its validation, and every model output for it."""
    site = cfg.site
    p = run.passes
    zone = site.time_zone
    keys = list(zip(p.train_id.tolist(), p.stamp_ns.tolist(), strict=True))
    reasons = rejection_reasons(p, site)
    cols = [
        Column("time_utc", "ISO 8601", "pass time (UTC, ns resolution)", np.array([format_iso_ns(t) for t in
                                                                                   p.stamp_ns.tolist()], object)),
        Column("time_local", zone, f"pass time in the site's zone ({zone})",
               np.array([format_local_ns(t, zone, seconds=True) for t in p.stamp_ns.tolist()], object)),
        Column("stamp_ns", "ns", "pass time, ns since the Unix epoch", p.stamp_ns),
        Column("train_id", "-", "train identifier", p.train_id),
        Column("vehicle_class", "-", "vehicle class", p.vehicle_class),
        Column("vehicle_count", "-", "vehicles in the consist", p.vehicle_count),
        Column("axle_count", "-", "axles in the consist", p.axle_count),
        Column("speed_mps", "m/s", "train speed", p.speed_mps),
        Column("speed_kmh", "km/h", "train speed", p.speed_mps * KMH_PER_MPS),
        Column("angle_of_attack_mrad", "mrad", "angle of attack of the leading wheelset", 1e3 * p.angle_of_attack_rad),
        Column("friction_state", "-", "friction state", np.array([FRICTION_NAMES.get(int(f), str(f))
                                                                  for f in p.friction_state], object)),
        Column("status", "-", "'processed', or why the models rejected the pass",
               np.array([r or "processed" for r in reasons.tolist()], object)),
    ]
    sq = run.squeal
    if len(sq.get("train_id", ())):
        i = _lookup(keys, list(zip(sq["train_id"].tolist(), sq["stamp_ns"].tolist(), strict=True)))
        risk = np.array(RISK_NAMES, object)[sq["risk"].astype(int)]
        regime = np.array([REGIME_NAMES[int(r)] for r in sq["regime"]], object)
        cols += [Column(f"squeal_{name}", unit, text, _pick(v, i, "")) for name, unit, text, v in (
            ("risk", "-", "squeal risk class", risk),
            ("regime", "-", "squeal regime", regime),
            ("level_dba", "dB(A)", "squeal sound pressure level at the receiver (empty: no squeal)", sq["level_dba"]),
            ("amplitude_mps", "m/s", "lateral wheel velocity amplitude A w", sq["velocity_amplitude_mps"]),
            ("crabbing_velocity_mps", "m/s", "crabbing velocity Vc", sq["crabbing_velocity_mps"]),
            ("frequency_hz", "Hz", "squeal frequency", sq["frequency_hz"]),
            ("friction_modifier_benefit_db", "dB", "predicted reduction with a friction modifier",
             sq["friction_modifier_benefit_db"]))]
    for model, nz in run.noise.items():
        i = _lookup(keys, list(zip(nz["train_id"].tolist(), nz["stamp_ns"].tolist(), strict=True)))
        cols += [
            Column(f"{model}_lpaeq_tp_dba", "dB(A)", f"rolling noise ({model}): LpAeq,Tp at the receiver",
                   _pick(nz["lpaeq_tp_dba"], i)),
            Column(f"{model}_lpafmax_dba", "dB(A)", f"rolling noise ({model}): LpAFmax at the receiver",
                   _pick(nz["lpafmax_dba"], i)),
            Column(f"{model}_tel_dba", "dB(A)", f"rolling noise ({model}): transit exposure level (ISO 3095)",
                   _pick(nz["tel_dba"], i)),
            Column(f"{model}_increase_since_grinding_db", "dB", f"rolling noise ({model}): LpAeq,Tp minus "
                   f"{INCREASE_REFERENCE}", _pick(nz["roughness_growth_increase_db"], i)),
        ]
    cols += _measured_columns(run, keys)
    cols += _state_columns(run, p.stamp_ns)
    return Table("passes", cols)


def _measured_columns(run: RunData, keys: list[tuple[str, int]]) -> list[Column]:
    """The measured pass-by and its residual per model (empty where a pass was not measured)."""
    cols = []
    if len(run.measured.get("train_id", ())):
        m = run.measured
        i = _lookup(keys, list(zip(m["train_id"].tolist(), m["stamp_ns"].tolist(), strict=True)))
        cols += [Column(f"measured_{name}", unit, text, _pick(m[name], i, "")) for name, unit, text in (
            ("lpaeq_tp_dba", "dB(A)", "measured LpAeq,Tp"), ("lpafmax_dba", "dB(A)", "measured LpAFmax"),
            ("tel_dba", "dB(A)", "measured TEL"), ("squeal_detected", "-", "the station's squeal flag"),
            ("squeal_frequency_hz", "Hz", "the measured squeal's tone (NaN: none, or not measured)"),
            ("squeal_level_db", "dB", "its tone level re 20 uPa"), ("squeal_duration_s", "s", "how long it lasted"),
            ("flanging_detected", "-", "flanging heard (broadband 4-10 kHz, no tone)"))]
    for model, r in run.residuals.items():
        i = _lookup(keys, list(zip(r["train_id"].tolist(), r["stamp_ns"].tolist(), strict=True)))
        cols += [Column(f"{model}_{name}", unit, f"measured minus predicted ({model}): {text}", _pick(r[name], i, ""))
                 for name, unit, text in (
                     ("residual_lpaeq_dba", "dB(A)", "LpAeq,Tp"),
                     ("residual_mid_db", "dB", "energy sum of the 500-2000 Hz bands"),
                     ("baseline_mid_db", "dB", "the site's running median of the 500-2000 Hz residual before the pass"),
                     ("excess_mid_db", "dB", "500-2000 Hz residual over the baseline (wheel-defect score)"),
                     ("loudest_vehicle_id", "-", "the vehicle segment loudest above its train's mean"),
                     ("loudest_vehicle_excess_db", "dB(A)", "its LpAeq over the train's energy mean"))]
    return cols


def _state_columns(run: RunData, stamps: np.ndarray) -> list[Column]:
    s = run.states
    if not s:
        return []
    k = np.searchsorted(s["stamp"], stamps, side="right") - 1  # the newest state at or before the pass
    worst = s["worst_band"].astype(int)
    rows = np.arange(len(worst))
    cols = [Column(f"corrugation_{name}", unit, text, _pick(v, k, None)) for name, unit, text, v in (
        ("worst_wavelength_mm", "mm", "wavelength of the band nearest its threshold", 1e3 * s["wavelength_m"][worst]),
        ("worst_rms_um", "µm", "r.m.s. corrugation of that band", 1e6 * s["amplitude_m"][rows, worst]),
        ("days_to_threshold", "d", "forecast days until that band reaches its threshold (empty: never)",
         s["days_to_threshold"]),
        ("grinding_due", "-", "a band is at or past its threshold", s["grinding_due"].astype(object)))]
    for b, lam in enumerate(s["wavelength_m"]):
        cols.append(Column(f"corrugation_rms_um_{1e3 * lam:.4g}mm", "µm", f"r.m.s. corrugation, {1e3 * lam:.4g} mm "
                           "band", _pick(1e6 * s["amplitude_m"][:, b], k)))
    return cols


def alert_table(run: RunData, cfg: SiteConfig) -> Table:
    """One row per alert event (a raise or a clear), in pass-time order."""
    zone = cfg.site.time_zone
    a = run.alerts
    col = lambda f: np.array([f(x) for x in a], object)  # noqa: E731
    return Table("alerts", [
        Column("time_utc", "ISO 8601", "pass time of the event (UTC)", col(lambda x: format_iso_ns(x.stamp_ns))),
        Column("time_local", zone, f"pass time of the event ({zone})",
               col(lambda x: format_local_ns(x.stamp_ns, zone, seconds=True))),
        Column("stamp_ns", "ns", "pass time of the event, ns since the Unix epoch",
               np.array([x.stamp_ns for x in a], np.int64)),
        Column("event", "-", "raised or cleared", col(lambda x: "raised" if x.active else "cleared")),
        Column("kind", "-", "alert kind", col(lambda x: KIND_NAMES.get(x.kind, str(x.kind)))),
        Column("key", "-", "what the alert is about (a band, a model, a train)", col(lambda x: x.key)),
        Column("severity", "-", "severity", col(lambda x: SEVERITY_NAMES[x.severity] if 0 <= x.severity < 3 else "")),
        Column("value", "see unit", "the value that raised or cleared it", np.array([x.value for x in a], float)),
        Column("threshold", "see unit", "its limit", np.array([x.threshold for x in a], float)),
        Column("unit", "-", "unit of value and threshold", col(lambda x: x.unit)),
        Column("summary", "-", "the alert's text", col(lambda x: x.summary)),
    ])


