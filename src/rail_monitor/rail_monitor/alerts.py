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

    def push_many(self, over: np.ndarray, near: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """push() each pair in order; returns the over and near counts and the window's length after
        each push (cumulative sums over the kept flags and the new ones)."""
        n, m = self.flags.maxlen or 0, len(over)
        kept = np.array(self.flags, dtype=np.int64).reshape(-1, 2)
        o = np.concatenate([kept[:, 0], np.asarray(over, bool)]).astype(np.int64)
        r = np.concatenate([kept[:, 1], np.asarray(near, bool)]).astype(np.int64)
        end = np.arange(len(kept) + 1, len(o) + 1)
        start = np.maximum(end - n, 0)
        co, cr = np.concatenate([[0], np.cumsum(o)]), np.concatenate([[0], np.cumsum(r)])
        over_counts, near_counts = co[end] - co[start], cr[end] - cr[start]
        if m:
            self.flags = deque(zip(o[-n:].astype(bool).tolist(), r[-n:].astype(bool).tolist(), strict=True),
                               maxlen=n)
            self.over, self.near = int(over_counts[-1]), int(near_counts[-1])
        return over_counts, near_counts, end - start


def hysteresis_changes(standing: bool, can_raise: np.ndarray, can_clear: np.ndarray) -> list[tuple[int, bool]]:
    """Where a hysteresis alert changes, in order: (index, active). From ``standing``, it is raised
    at the first can_raise while down and cleared at the first can_clear (a later index) while up."""
    ups, downs = np.flatnonzero(can_raise), np.flatnonzero(can_clear)
    out: list[tuple[int, bool]] = []
    i = 0
    while True:
        idx = downs if standing else ups
        k = int(np.searchsorted(idx, i))
        if k == len(idx):
            return out
        i = int(idx[k])
        standing = not standing
        out.append((i, standing))
        i += 1


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

    def _windowed_change(self, active: bool, kind: int, key: str, stamp_ns: int, what: str, threshold_text: str,
                         unit: str, value: float, threshold: float) -> Alert | None:
        if active:
            return self._set(True, kind, key, stamp_ns, SEVERITY_WARNING, f"{what} ({threshold_text})", value,
                             threshold, unit)
        return self._set(False, kind, key, stamp_ns, SEVERITY_INFO, f"{what}: cleared", value, threshold, unit)

    def _windowed(self, kind: int, key: str, stamp_ns: int, can_raise: bool, can_clear: bool, what: str,
                  threshold_text: str, unit: str, value: float, threshold: float) -> list[Alert]:
        standing = (kind, key) in self.standing
        if not (can_clear if standing else can_raise):
            return []
        e = self._windowed_change(not standing, kind, key, stamp_ns, what, threshold_text, unit, value, threshold)
        return [e] if e else []

    def _windowed_series(self, kind: int, key: str, stamp_ns: np.ndarray, can_raise: np.ndarray,
                         can_clear: np.ndarray, what: str, threshold_text: Any, unit: str, value: np.ndarray,
                         threshold: float) -> list[Alert]:
        """_windowed over a series: only where the alert changes (threshold_text(i): the text at i)."""
        out = [self._windowed_change(active, kind, key, int(stamp_ns[i]), what, threshold_text(i), unit,
                                     float(value[i]), threshold)
               for i, active in hysteresis_changes((kind, key) in self.standing, can_raise, can_clear)]
        return [e for e in out if e]

    # -- inputs -----------------------------------------------------------------------------------
    # Each input has a one-message form (the reference; the node's train_pass path) and a series
    # form over many messages of one stream at once (batch mode, the node's taken backlogs), which
    # gives the same events and leaves the same state (tests/test_alerts.py checks one against
    # the other on random streams).

    def _band_change(self, active: bool, key: str, stamp_ns: int, lam: float, z: float, t: float) -> Alert | None:
        if active:
            return self._set(True, KIND_GRINDING_DUE, key, stamp_ns, SEVERITY_CRITICAL,
                             f"grinding due: {1e3 * lam:.1f} mm band at {1e6 * z:.2f} um r.m.s., "
                             f"threshold {1e6 * t:.2f} um", z, t, "m")
        return self._set(False, KIND_GRINDING_DUE, key, stamp_ns, SEVERITY_INFO,
                         f"grinding due: {1e3 * lam:.1f} mm band cleared at {1e6 * z:.2f} um r.m.s.", z, t, "m")

    def _forecast_change(self, active: bool, stamp_ns: int, days: float, due_standing: bool,
                         due_ns: int) -> Alert | None:
        lead = self.cfg["lead_time_days"]
        if active:
            return self._set(True, KIND_GRINDING_FORECAST, "forecast", stamp_ns, SEVERITY_WARNING,
                             f"grinding forecast in {days:.1f} days, inside the {lead:g}-day lead time",
                             days, lead, "day", due_ns)
        why = "grinding is due" if due_standing else f"forecast {days:.1f} days"
        return self._set(False, KIND_GRINDING_FORECAST, "forecast", stamp_ns, SEVERITY_INFO,
                         f"grinding forecast cleared: {why}", days, lead, "day")

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
            events.append(self._band_change(bool(over[i]), keys[i], stamp_ns, float(wl[i]), float(amp[i]),
                                            float(thr[i])))
        due_standing = any(kind == KIND_GRINDING_DUE for kind, _ in self.standing)
        forecast_standing = (KIND_GRINDING_FORECAST, "forecast") in self.standing
        if grinding_due and not due_standing:
            events.append(self._forecast_change(True, stamp_ns, days_to_threshold, due_standing, grinding_due_ns))
        elif (due_standing or days_to_threshold > self.cfg["forecast_clear_factor"] * self.cfg["lead_time_days"]) \
                and forecast_standing:
            events.append(self._forecast_change(False, stamp_ns, days_to_threshold, due_standing, 0))
        return [e for e in events if e]

    def on_states(self, stamp_ns: np.ndarray, wavelength_m: np.ndarray, amplitude_m: np.ndarray,
                  threshold_m: np.ndarray, days_to_threshold: np.ndarray, grinding_due: np.ndarray,
                  grinding_due_ns: np.ndarray) -> list[Alert]:
        """on_state over K states of the same bands, in order: amplitude_m (K, B); stamp_ns,
        days_to_threshold, grinding_due, grinding_due_ns (K,); wavelength_m, threshold_m (B,)."""
        stamps = np.asarray(stamp_ns, np.int64)
        wl, thr = np.asarray(wavelength_m, float), np.asarray(threshold_m, float)
        amp = np.asarray(amplitude_m, float).reshape(len(stamps), len(wl))
        days, due = np.asarray(days_to_threshold, float), np.asarray(grinding_due, bool)
        due_ns = np.asarray(grinding_due_ns, np.int64)
        keys = self._band_keys(wl)
        if len(set(keys)) < len(keys):  # two bands share a key: their alerts interact, go state by state
            return [e for k in range(len(stamps)) for e in self.on_state(
                int(stamps[k]), wl, amp[k], thr, float(days[k]), bool(due[k]), int(due_ns[k]))]
        over = amp >= thr
        under = ~over & (amp < self.cfg["grinding_clear_fraction"] * thr)
        changes: list[tuple[int, int, bool]] = []  # (state, band; len(keys) for the forecast, active)
        up = np.empty(amp.shape, bool)  # band's alert standing after each state
        for b, key in enumerate(keys):
            was = (KIND_GRINDING_DUE, key) in self.standing
            band = hysteresis_changes(was, over[:, b], under[:, b])
            flips = np.zeros(len(stamps), np.int64)
            flips[[i for i, _ in band]] = 1
            up[:, b] = was ^ (np.cumsum(flips) % 2 == 1)
            changes += [(i, b, active) for i, active in band]
        others = any(kind == KIND_GRINDING_DUE and k not in keys for kind, k in self.standing)
        due_standing = up.any(axis=1) | others
        fkey = (KIND_GRINDING_FORECAST, "forecast")
        can_raise = due & ~due_standing
        beyond = days > self.cfg["forecast_clear_factor"] * self.cfg["lead_time_days"]
        can_clear = ~can_raise & (due_standing | beyond)
        forecast = hysteresis_changes(fkey in self.standing, can_raise, can_clear)
        changes += [(i, len(keys), active) for i, active in forecast]
        events: list[Alert | None] = []
        for i, b, active in sorted(changes):
            if b < len(keys):
                events.append(self._band_change(active, keys[b], int(stamps[i]), float(wl[b]), float(amp[i, b]),
                                                float(thr[b])))
            else:
                events.append(self._forecast_change(active, int(stamps[i]), float(days[i]), bool(due_standing[i]),
                                                    int(due_ns[i]) if active else 0))
        # A standing forecast follows each newer due time (as on_state's raise of a standing one does).
        if fkey in self.standing:
            since = forecast[-1][0] + 1 if forecast else 0
            old = self.standing[fkey]
            seq = since + np.flatnonzero(can_raise[since:] & (due_ns[since:] != 0))
            prev = np.concatenate([[old.due_ns], due_ns[seq[:-1]]])
            moved = seq[due_ns[seq] != prev]
            if len(moved):
                self.standing[fkey] = replace(old, due_ns=int(due_ns[moved[-1]]), value=float(days[moved[-1]]))
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

    def _noise_what(self, model: str) -> str:
        return f"{model} {self.cfg['noise_metric'][:-4]} above {self.cfg['noise_limit_dba']:g} dB(A)"

    def on_noise(self, stamp_ns: int, model: str, values: Mapping[str, float]) -> list[Alert]:
        """A RollingNoise prediction (values: its single-number fields) of one source model."""
        metric, limit = self.cfg["noise_metric"], self.cfg["noise_limit_dba"]
        level = float(values[metric])
        w = self._noise.setdefault(model, _Window(self.cfg["noise_window_passes"]))
        w.push(level > limit, level > limit - self.cfg["noise_hysteresis_db"])
        n = self.cfg["noise_window_passes"]
        return self._windowed(KIND_NOISE_LIMIT, model, stamp_ns, w.over >= self.cfg["noise_raise_count"],
                              w.near <= self.cfg["noise_clear_count"], self._noise_what(model),
                              f"{w.over} of the last {n} passes, this one {level:.1f} dB(A)", "dB(A)", level, limit)

    def on_noise_series(self, stamp_ns: np.ndarray, model: str, values: Mapping[str, np.ndarray]) -> list[Alert]:
        """on_noise over one source model's predictions in order (values: arrays of the fields)."""
        metric, limit = self.cfg["noise_metric"], self.cfg["noise_limit_dba"]
        level = np.asarray(values[metric], float)
        w = self._noise.setdefault(model, _Window(self.cfg["noise_window_passes"]))
        over, near, _ = w.push_many(level > limit, level > limit - self.cfg["noise_hysteresis_db"])
        n = self.cfg["noise_window_passes"]
        return self._windowed_series(KIND_NOISE_LIMIT, model, stamp_ns, over >= self.cfg["noise_raise_count"],
                                     near <= self.cfg["noise_clear_count"], self._noise_what(model),
                                     lambda i: f"{over[i]} of the last {n} passes, this one {level[i]:.1f} dB(A)",
                                     "dB(A)", level, limit)

    def _share(self, w: _Window, hit: bool, kind: int, key: str, stamp_ns: int, name: str, what: str,
               full_window: bool) -> list[Alert]:
        """A share-of-window alert: raised at ``<name>_raise_share`` of the whole window (only once the
        window is full, with full_window), cleared at or below ``<name>_clear_share`` of what it holds."""
        w.push(hit, hit)
        n = len(w.flags)
        raise_share, share = self.cfg[f"{name}_raise_share"], w.over / n
        raise_at = w.flags.maxlen * raise_share if n == w.flags.maxlen or not full_window else float("inf")
        return self._windowed(kind, key, stamp_ns, w.over >= max(raise_at, 1),
                              w.near <= self.cfg[f"{name}_clear_share"] * n, what,
                              f"{w.over} of the last {n}, {share:.0%}", "-", share, raise_share)

    def _share_series(self, w: _Window, hits: np.ndarray, kind: int, key: str, stamp_ns: np.ndarray, name: str,
                      what: str, full_window: bool) -> list[Alert]:
        """_share over a series of hits."""
        over, near, n = w.push_many(hits, hits)
        raise_share, share = self.cfg[f"{name}_raise_share"], over / n
        raise_at = np.where((n == w.flags.maxlen) | (not full_window), w.flags.maxlen * raise_share, np.inf)
        return self._windowed_series(kind, key, stamp_ns, over >= np.maximum(raise_at, 1),
                                     near <= self.cfg[f"{name}_clear_share"] * n, what,
                                     lambda i: f"{over[i]} of the last {n[i]}, {share[i]:.0%}", "-", share,
                                     raise_share)

    def _squeal_what(self) -> str:
        return f"squeal risk {self.cfg['squeal_min_risk']} or above"

    def on_squeal(self, stamp_ns: int, risk: int) -> list[Alert]:
        """A SquealPrediction's risk (RISK_*). The window must be full: a share over the first few
        passes would raise on the first squeal."""
        return self._share(self._squeal, int(risk) >= self._min_risk, KIND_SQUEAL, "site", stamp_ns, "squeal",
                           self._squeal_what(), full_window=True)

    def on_squeal_series(self, stamp_ns: np.ndarray, risk: np.ndarray) -> list[Alert]:
        """on_squeal over SquealPredictions in order."""
        return self._share_series(self._squeal, np.asarray(risk) >= self._min_risk, KIND_SQUEAL, "site",
                                  np.asarray(stamp_ns), "squeal", self._squeal_what(), full_window=True)

    def on_train_pass(self, stamp_ns: int, rejected: bool) -> list[Alert]:
        """A TrainPass message, rejected or not."""
        return self._share(self._rejected, rejected, KIND_INPUT_REJECTED, "train_pass", stamp_ns, "rejected",
                           "train passes rejected", full_window=False)

    def on_train_pass_series(self, stamp_ns: np.ndarray, rejected: np.ndarray) -> list[Alert]:
        """on_train_pass over TrainPass messages in order."""
        return self._share_series(self._rejected, np.asarray(rejected, bool), KIND_INPUT_REJECTED, "train_pass",
                                  np.asarray(stamp_ns), "rejected", "train passes rejected", full_window=False)


def describe(alert: Alert) -> str:
    """One line for people: pass time, raised/cleared, kind, summary."""
    verb = "raised " if alert.active else "cleared"
    return f"{format_iso_ns(alert.stamp_ns)}  {verb}  {KIND_NAMES[alert.kind]:17s} {alert.summary}"
