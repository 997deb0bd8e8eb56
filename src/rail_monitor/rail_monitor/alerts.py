"""Wayside alerts from the model outputs: raised and cleared with hysteresis (no ROS).

Shared by the ``alert_manager`` node and batch mode; each input stream feeds its own alerts, so
the alerts depend only on each stream's order, not on how streams interleave.

- GRINDING_DUE, one per band (key: the band's centre wavelength): raised when the band's r.m.s.
  reaches its intervention threshold, cleared when it is below ``grinding_clear_fraction`` of it
  (after grinding).
- GRINDING_FORECAST (key ``forecast``): raised when the state's forecast reaches a threshold within
  the corrugation lead time (CorrugationState.grinding_due) while no GRINDING_DUE stands; cleared
  when the forecast is beyond ``forecast_clear_factor`` x the lead time, or when a GRINDING_DUE
  stands (it supersedes the forecast).
- NOISE_LIMIT, one per source model: raised when at least ``noise_raise_count`` of the last
  ``noise_window_passes`` passes exceed ``noise_limit_dba`` on ``noise_metric``; cleared when at
  most ``noise_clear_count`` of them exceed the limit minus ``noise_hysteresis_db``.
- SQUEAL (key ``site``): the same on the share of the last ``squeal_window_passes`` passes whose
  squeal risk is at least ``squeal_min_risk``: raised at ``squeal_raise_share``, cleared at or below
  ``squeal_clear_share``.
- INPUT_REJECTED (key ``train_pass``): the same on the rejected share of the last
  ``rejected_window_passes`` TrainPass messages.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rail_monitor.errors import ConfigError
from rail_monitor.params import ParamSpec, ParamValues, resolve, section
from rail_monitor.timeutil import format_iso_ns

# WaysideAlert.KIND_* and SEVERITY_* values.
KIND_GRINDING_DUE, KIND_GRINDING_FORECAST, KIND_NOISE_LIMIT, KIND_SQUEAL, KIND_INPUT_REJECTED = range(1, 6)
KIND_NAMES = {KIND_GRINDING_DUE: "grinding due", KIND_GRINDING_FORECAST: "grinding forecast",
              KIND_NOISE_LIMIT: "noise limit", KIND_SQUEAL: "squeal", KIND_INPUT_REJECTED: "inputs rejected"}
SEVERITY_INFO, SEVERITY_WARNING, SEVERITY_CRITICAL = range(3)
NOISE_METRICS = ("lpaeq_tp_dba", "lpafmax_dba", "tel_dba")  # RollingNoise single numbers
RISK_NAMES = ("none", "low", "medium", "high")

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
)


@dataclass(frozen=True)
class AlertConfig(ParamValues):
    """The site's alert parameters (names and units as in ALERT_SPECS), with the corrugation lead time."""


def alert_config(values: Mapping[str, Any], lead_time_days: float, prefix: str = "alerts.") -> AlertConfig:
    """Checked alert parameters from flat values (keys under prefix); ConfigError without hysteresis."""
    out = resolve(ALERT_SPECS, section(values, prefix), where=prefix, strict=True)
    for name, raise_key, clear_key in (("noise", "noise_raise_count", "noise_clear_count"),
                                       ("squeal", "squeal_raise_share", "squeal_clear_share"),
                                       ("rejected", "rejected_raise_share", "rejected_clear_share")):
        if out[clear_key] >= out[raise_key]:
            raise ConfigError(f"parameter '{prefix}{clear_key}' must be below '{prefix}{raise_key}' "
                              f"(the {name} alert needs hysteresis)")
    if out["noise_raise_count"] > out["noise_window_passes"]:
        raise ConfigError(f"parameter '{prefix}noise_raise_count' exceeds '{prefix}noise_window_passes'")
    out["lead_time_days"] = float(lead_time_days)
    return AlertConfig(out)


@dataclass(frozen=True)
class Alert:
    """One raise or clear (fields and units as in rail_msgs/WaysideAlert; times in ns)."""

    kind: int
    key: str
    severity: int
    active: bool
    summary: str
    value: float
    threshold: float
    unit: str
    stamp_ns: int
    raised_ns: int
    due_ns: int = 0


class _Window:
    """Counts of two flags (raise level, clear level) over the last n inputs."""

    def __init__(self, n: int) -> None:
        self.flags: deque[tuple[bool, bool]] = deque(maxlen=n)
        self.over = self.near = 0

    def push(self, over: bool, near: bool) -> None:
        if len(self.flags) == self.flags.maxlen:
            o, n = self.flags[0]
            self.over -= o
            self.near -= n
        self.flags.append((over, near))
        self.over += over
        self.near += near


class AlertManager:
    """The standing alerts of one site and the raise/clear events that change them."""

    def __init__(self, cfg: AlertConfig) -> None:
        self.cfg = cfg
        self.standing: dict[tuple[int, str], Alert] = {}
        self.events: list[Alert] = []
        self._noise: dict[str, _Window] = {}
        self._squeal = _Window(cfg["squeal_window_passes"])
        self._rejected = _Window(cfg["rejected_window_passes"])
        self._min_risk = RISK_NAMES.index(cfg["squeal_min_risk"])
        self._keys: dict[bytes, list[str]] = {}

    # -- raise / clear ----------------------------------------------------------------------------
    def _set(self, active: bool, kind: int, key: str, stamp_ns: int, severity: int, summary: str, value: float,
             threshold: float, unit: str, due_ns: int = 0) -> Alert | None:
        """Raise or clear (kind, key) if that changes it; return the event or None."""
        old = self.standing.get((kind, key))
        if active == (old is not None):
            if old is not None and due_ns and due_ns != old.due_ns:  # keep a standing forecast current
                self.standing[(kind, key)] = replace(old, due_ns=due_ns, value=value)
            return None
        raised = stamp_ns if active else old.raised_ns
        event = Alert(kind, key, severity, active, summary, float(value), float(threshold), unit, int(stamp_ns),
                      int(raised), int(due_ns))
        if active:
            self.standing[(kind, key)] = event
        else:
            del self.standing[(kind, key)]
        self.events.append(event)
        return event

    def _windowed(self, window: _Window, kind: int, key: str, stamp_ns: int, raise_at: float, clear_at: float,
                  what: str, threshold_text: str, unit: str, value: float, threshold: float) -> list[Alert]:
        standing = (kind, key) in self.standing
        if not standing and window.over >= raise_at:
            e = self._set(True, kind, key, stamp_ns, SEVERITY_WARNING, f"{what} ({threshold_text})", value,
                          threshold, unit)
        elif standing and window.near <= clear_at:
            e = self._set(False, kind, key, stamp_ns, SEVERITY_INFO, f"{what}: cleared", value, threshold, unit)
        else:
            return []
        return [e] if e else []

    # -- inputs -----------------------------------------------------------------------------------
    def on_state(self, stamp_ns: int, wavelength_m: np.ndarray, amplitude_m: np.ndarray, threshold_m: np.ndarray,
                 days_to_threshold: float, grinding_due: bool, grinding_due_ns: int) -> list[Alert]:
        """A corrugation state (CorrugationState fields)."""
        events: list[Alert | None] = []
        wl = np.asarray(wavelength_m, float)
        amp, thr = np.asarray(amplitude_m, float), np.asarray(threshold_m, float)
        keys = self._band_keys(wl)
        standing = np.array([(KIND_GRINDING_DUE, k) in self.standing for k in keys], dtype=bool)
        over = amp >= thr
        under = ~over & (amp < self.cfg["grinding_clear_fraction"] * thr)
        # Only the bands whose alert changes (a raise or clear of a standing one is a no-op).
        for i in np.flatnonzero((over & ~standing) | (under & standing)).tolist():
            lam, z, t = float(wl[i]), float(amp[i]), float(thr[i])
            if over[i]:
                events.append(self._set(True, KIND_GRINDING_DUE, keys[i], stamp_ns, SEVERITY_CRITICAL,
                                        f"grinding due: {1e3 * lam:.1f} mm band at {1e6 * z:.2f} um r.m.s., "
                                        f"threshold {1e6 * t:.2f} um", z, t, "m"))
            else:
                events.append(self._set(False, KIND_GRINDING_DUE, keys[i], stamp_ns, SEVERITY_INFO,
                                        f"grinding due: {1e3 * lam:.1f} mm band cleared at {1e6 * z:.2f} um r.m.s.",
                                        z, t, "m"))
        lead = self.cfg["lead_time_days"]
        due_standing = any(kind == KIND_GRINDING_DUE for kind, _ in self.standing)
        if grinding_due and not due_standing:
            events.append(self._set(True, KIND_GRINDING_FORECAST, "forecast", stamp_ns, SEVERITY_WARNING,
                                    f"grinding forecast in {days_to_threshold:.1f} days, inside the {lead:g}-day "
                                    "lead time", days_to_threshold, lead, "day", grinding_due_ns))
        elif (due_standing or days_to_threshold > self.cfg["forecast_clear_factor"] * lead) \
                and (KIND_GRINDING_FORECAST, "forecast") in self.standing:
            why = "grinding is due" if due_standing else f"forecast {days_to_threshold:.1f} days"
            events.append(self._set(False, KIND_GRINDING_FORECAST, "forecast", stamp_ns, SEVERITY_INFO,
                                    f"grinding forecast cleared: {why}", days_to_threshold, lead, "day"))
        return [e for e in events if e]

    def _band_keys(self, wavelength_m: np.ndarray) -> list[str]:
        """The alert key of each band (its centre wavelength), formatted once per set of bands."""
        cache_key = wavelength_m.tobytes()
        keys = self._keys.get(cache_key)
        if keys is None:
            if len(self._keys) >= 16:  # bands change only with the site's configuration
                self._keys.clear()
            keys = self._keys[cache_key] = [f"{lam:.4f}m" for lam in wavelength_m.tolist()]
        return keys

    def on_noise(self, stamp_ns: int, model: str, values: Mapping[str, float]) -> list[Alert]:
        """A RollingNoise prediction (values: its single-number fields) of one source model."""
        metric, limit = self.cfg["noise_metric"], self.cfg["noise_limit_dba"]
        level = float(values[metric])
        w = self._noise.setdefault(model, _Window(self.cfg["noise_window_passes"]))
        w.push(level > limit, level > limit - self.cfg["noise_hysteresis_db"])
        n = self.cfg["noise_window_passes"]
        return self._windowed(w, KIND_NOISE_LIMIT, model, stamp_ns, self.cfg["noise_raise_count"],
                              self.cfg["noise_clear_count"], f"{model} {metric[:-4]} above {limit:g} dB(A)",
                              f"{w.over} of the last {n} passes, this one {level:.1f} dB(A)", "dB(A)", level, limit)

    def _share(self, w: _Window, hit: bool, kind: int, key: str, stamp_ns: int, name: str, what: str,
               full_window: bool) -> list[Alert]:
        """A share-of-window alert: raised at ``<name>_raise_share`` of the whole window (only once the
        window is full, with full_window), cleared at or below ``<name>_clear_share`` of what it holds."""
        w.push(hit, hit)
        n = len(w.flags)
        raise_share, share = self.cfg[f"{name}_raise_share"], w.over / n
        raise_at = w.flags.maxlen * raise_share if n == w.flags.maxlen or not full_window else float("inf")
        return self._windowed(w, kind, key, stamp_ns, max(raise_at, 1), self.cfg[f"{name}_clear_share"] * n, what,
                              f"{w.over} of the last {n}, {share:.0%}", "-", share, raise_share)

    def on_squeal(self, stamp_ns: int, risk: int) -> list[Alert]:
        """A SquealPrediction's risk (RISK_*). The window must be full: a share over the first few
        passes would raise on the first squeal."""
        return self._share(self._squeal, int(risk) >= self._min_risk, KIND_SQUEAL, "site", stamp_ns, "squeal",
                           f"squeal risk {self.cfg['squeal_min_risk']} or above", full_window=True)

    def on_train_pass(self, stamp_ns: int, rejected: bool) -> list[Alert]:
        """A TrainPass message, rejected or not."""
        return self._share(self._rejected, rejected, KIND_INPUT_REJECTED, "train_pass", stamp_ns, "rejected",
                           "train passes rejected", full_window=False)


def describe(alert: Alert) -> str:
    """One line for people: pass time, raised/cleared, kind, summary."""
    verb = "raised " if alert.active else "cleared"
    return f"{format_iso_ns(alert.stamp_ns)}  {verb}  {KIND_NAMES[alert.kind]:17s} {alert.summary}"
