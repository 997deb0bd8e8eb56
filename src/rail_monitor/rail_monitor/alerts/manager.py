"""The standing alerts of a site and the raise/clear events that change them (no ROS).

The rules are in :mod:`rail_monitor.alerts`; thresholds in :mod:`rail_monitor.alerts.config`.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rail_monitor.alerts.config import (
    KIND_GRINDING_DUE,
    KIND_GRINDING_FORECAST,
    KIND_INPUT_REJECTED,
    KIND_NAMES,
    KIND_NOISE_DRIFT,
    KIND_NOISE_LIMIT,
    KIND_SQUEAL,
    KIND_SQUEAL_DRIFT,
    KIND_SQUEAL_MEASURED,
    KIND_SQUEAL_MISMATCH,
    KIND_SQUEAL_OFFENDER,
    KIND_WHEEL_DEFECT,
    SEVERITY_CRITICAL,
    SEVERITY_INFO,
    SEVERITY_WARNING,
    AlertConfig,
    counts_as_squeal,
)
from rail_monitor.alerts.squeal_drift import SquealDrift
from rail_monitor.alerts.squealers import RepeatSquealers
from rail_monitor.alerts.windows import Window, hysteresis_changes
from rail_monitor.core.text import printable
from rail_monitor.core.timeutil import format_iso_ns

# Wheel-defect keys whose flags are counted: past this many, the most flagged half is kept (a key
# per train id, new every pass, would otherwise grow without end on a box running for years).
OFFENDERS_KEPT = 10_000


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


class AlertManager:
    """The standing alerts of one site and the raise/clear events that change them."""

    def __init__(self, cfg: AlertConfig) -> None:
        self.cfg = cfg
        self.standing: dict[tuple[int, str], Alert] = {}
        self.events: list[Alert] = []  # since the last take_events(): a long-running caller takes them
        self.raised = self.cleared = 0  # every raise and clear so far
        self._noise: dict[str, Window] = {}
        self._squeal = Window(cfg.squeal_window_passes)
        self._rejected = Window(cfg.rejected_window_passes)
        self._keys: dict[bytes, list[str]] = {}
        self.offences: Counter[str] = Counter()  # passes flagged per wheel-defect key (repeat offenders)
        self._mismatch = {k: Window(cfg.squeal_mismatch_window_passes) for k in MISMATCHES}
        self._heard = Window(cfg.squeal_measured_window_passes)
        self.squealers = RepeatSquealers(cfg.squeal_offender_window_passes, cfg.squeal_offender_min_passes,
                                         cfg.squeal_offender_raise_p, cfg.squeal_offender_clear_p)
        self.drift = SquealDrift(cfg.squeal_drift_windows, cfg.squeal_drift_min_passes)

    def retune(self, cfg: AlertConfig) -> None:
        """Take new limits and windows (a running node's parameters changed): each window keeps its
        newest flags; standing alerts stay until the new limits clear them."""
        self.cfg = cfg
        self._noise = {model: w.resized(cfg.noise_window_passes) for model, w in self._noise.items()}
        self._squeal = self._squeal.resized(cfg.squeal_window_passes)
        self._rejected = self._rejected.resized(cfg.rejected_window_passes)
        self._mismatch = {k: w.resized(cfg.squeal_mismatch_window_passes) for k, w in self._mismatch.items()}
        self._heard = self._heard.resized(cfg.squeal_measured_window_passes)
        s = self.squealers
        s.window, s.min_passes, s.raise_p, s.clear_p = (cfg.squeal_offender_window_passes,
                                                        cfg.squeal_offender_min_passes,
                                                        cfg.squeal_offender_raise_p, cfg.squeal_offender_clear_p)
        self.drift.windows, self.drift.min_passes = cfg.squeal_drift_windows, cfg.squeal_drift_min_passes

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
            self.raised += 1
        else:
            del self.standing[(kind, key)]
            self.cleared += 1
        self.events.append(event)
        return event

    def take_events(self) -> list[Alert]:
        """The raise and clear events since the last call, in the order made; the manager forgets
        them (a node running for years must not keep every event)."""
        out, self.events = self.events, []
        return out

    def _windowed_change(self, active: bool, kind: int, key: str, stamp_ns: int, what: str, threshold_text: str,
                         unit: str, value: float, threshold: float) -> Alert | None:
        if active:
            return self._set(True, kind, key, stamp_ns, SEVERITY_WARNING, f"{what} ({threshold_text})", value,
                             threshold, unit)
        return self._set(False, kind, key, stamp_ns, SEVERITY_INFO, f"{what}: cleared", value, threshold, unit)

    def _windowed(self, kind: int, key: str, stamp_ns: np.ndarray, can_raise: np.ndarray, can_clear: np.ndarray,
                  what: str, threshold_text: Any, unit: str, value: np.ndarray, threshold: float) -> list[Alert]:
        """A window alert over a series: events only where it changes (threshold_text(i): the text at i)."""
        out = [self._windowed_change(active, kind, key, int(stamp_ns[i]), what, threshold_text(i), unit,
                                     float(value[i]), threshold)
               for i, active in hysteresis_changes((kind, key) in self.standing, can_raise, can_clear)]
        return [e for e in out if e]

    # -- inputs -----------------------------------------------------------------------------------
    # Each input takes a series of one stream's messages in order (one message is a series of
    # length 1): batch mode feeds a whole stream, the node each backlog it takes.

    def _band_change(self, active: bool, key: str, stamp_ns: int, lam: float, z: float, t: float) -> Alert | None:
        if active:
            return self._set(True, KIND_GRINDING_DUE, key, stamp_ns, SEVERITY_CRITICAL,
                             f"grinding due: {1e3 * lam:.1f} mm band at {1e6 * z:.2f} um r.m.s., "
                             f"threshold {1e6 * t:.2f} um", z, t, "m")
        return self._set(False, KIND_GRINDING_DUE, key, stamp_ns, SEVERITY_INFO,
                         f"grinding due: {1e3 * lam:.1f} mm band cleared at {1e6 * z:.2f} um r.m.s.", z, t, "m")

    def _forecast_change(self, active: bool, stamp_ns: int, days: float, due_standing: bool,
                         due_ns: int) -> Alert | None:
        lead = self.cfg.lead_time_days
        if active:
            return self._set(True, KIND_GRINDING_FORECAST, "forecast", stamp_ns, SEVERITY_WARNING,
                             f"grinding forecast in {days:.1f} days, inside the {lead:g}-day lead time",
                             days, lead, "day", due_ns)
        why = "grinding is due" if due_standing else f"forecast {days:.1f} days"
        return self._set(False, KIND_GRINDING_FORECAST, "forecast", stamp_ns, SEVERITY_INFO,
                         f"grinding forecast cleared: {why}", days, lead, "day")

    def on_states(self, stamp_ns: np.ndarray, wavelength_m: np.ndarray, amplitude_m: np.ndarray,
                  threshold_m: np.ndarray, days_to_threshold: np.ndarray, grinding_due: np.ndarray,
                  grinding_due_ns: np.ndarray) -> list[Alert]:
        """K corrugation states of the same bands, in order (CorrugationState fields): amplitude_m
        (K, B) [m]; stamp_ns [ns], days_to_threshold [day], grinding_due, grinding_due_ns [ns] (K,);
        wavelength_m, threshold_m (B,) [m]."""
        stamps = np.asarray(stamp_ns, np.int64)
        wl, thr = np.asarray(wavelength_m, float), np.asarray(threshold_m, float)
        amp = np.asarray(amplitude_m, float).reshape(len(stamps), len(wl))
        days, due = np.asarray(days_to_threshold, float), np.asarray(grinding_due, bool)
        due_ns = np.asarray(grinding_due_ns, np.int64)
        keys = self._band_keys(wl)
        over = amp >= thr
        under = ~over & (amp < self.cfg.grinding_clear_fraction * thr)
        changes: list[tuple[int, int, bool]] = []  # (state, band; len(keys) for the forecast, active)
        was = np.array([(KIND_GRINDING_DUE, key) in self.standing for key in keys], bool)
        up = np.broadcast_to(was, amp.shape).copy()  # band's alert standing after each state
        # Only a band over its threshold while down, or under its clear level while up, can change.
        for b in np.flatnonzero(np.where(was, under.any(axis=0), over.any(axis=0))).tolist():
            band = hysteresis_changes(bool(was[b]), over[:, b], under[:, b])
            flips = np.zeros(len(stamps), np.int64)
            flips[[i for i, _ in band]] = 1
            up[:, b] = was[b] ^ (np.cumsum(flips) % 2 == 1)
            changes += [(i, b, active) for i, active in band]
        others = any(kind == KIND_GRINDING_DUE and k not in keys for kind, k in self.standing)
        due_standing = up.any(axis=1) | others
        fkey = (KIND_GRINDING_FORECAST, "forecast")
        can_raise = due & ~due_standing
        beyond = days > self.cfg.forecast_clear_factor * self.cfg.lead_time_days
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
        # A standing forecast follows each newer due time (_set keeps it current).
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
        """The alert key of each band (its centre wavelength to 0.1 mm), formatted once per set of
        bands; unique by construction (full precision, then an index, where bands are closer)."""
        cache_key = wavelength_m.tobytes()
        keys = self._keys.get(cache_key)
        if keys is None:
            if len(self._keys) >= 16:  # bands change only with the site's configuration
                self._keys.clear()
            keys = [f"{lam:.4f}m" for lam in wavelength_m.tolist()]
            if len(set(keys)) < len(keys):
                keys = [f"{lam!r}m" for lam in wavelength_m.tolist()]
            if len(set(keys)) < len(keys):
                keys = [f"{k}#{i}" for i, k in enumerate(keys)]
            self._keys[cache_key] = keys
        return keys

    def _noise_what(self, model: str) -> str:
        return f"{model} {self.cfg.noise_metric[:-4]} above {self.cfg.noise_limit_dba:g} dB(A)"

    def on_noise(self, stamp_ns: np.ndarray, model: str, values: Mapping[str, np.ndarray]) -> list[Alert]:
        """RollingNoise predictions of one source model in order (values: arrays of their single-number
        fields, at least ``noise_metric``)."""
        metric, limit = self.cfg.noise_metric, self.cfg.noise_limit_dba
        level = np.asarray(values[metric], float)
        w = self._noise.setdefault(model, Window(self.cfg.noise_window_passes))
        over, near, _ = w.push(level > limit, level > limit - self.cfg.noise_hysteresis_db)
        n = self.cfg.noise_window_passes
        return self._windowed(KIND_NOISE_LIMIT, model, stamp_ns, over >= self.cfg.noise_raise_count,
                              near <= self.cfg.noise_clear_count, self._noise_what(model),
                              lambda i: f"{over[i]} of the last {n} passes, this one {level[i]:.1f} dB(A)",
                              "dB(A)", level, limit)

    def _share(self, w: Window, hits: np.ndarray, kind: int, key: str, stamp_ns: np.ndarray, name: str,
               what: str, full_window: bool) -> list[Alert]:
        """A share-of-window alert over a series of hits: raised at ``<name>_raise_share`` of the whole
        window (only once the window is full, with full_window), cleared at or below
        ``<name>_clear_share`` of what it holds."""
        over, near, n = w.push(hits, hits)
        raise_share, share = getattr(self.cfg, f"{name}_raise_share"), over / n
        raise_at = np.where((n == w.flags.maxlen) | (not full_window), w.flags.maxlen * raise_share, np.inf)
        return self._windowed(kind, key, stamp_ns, over >= np.maximum(raise_at, 1),
                              near <= getattr(self.cfg, f"{name}_clear_share") * n, what,
                              lambda i: f"{over[i]} of the last {n[i]}, {share[i]:.0%}", "-", share,
                              raise_share)

    def _squeal_what(self) -> str:
        return f"squeal risk {self.cfg.squeal_min_risk} or above"

    def on_squeal(self, stamp_ns: np.ndarray, risk: np.ndarray) -> list[Alert]:
        """SquealPredictions' risks (RISK_*) in order. The window must be full: a share over the
        first few passes would raise on the first squeal."""
        return self._share(self._squeal, counts_as_squeal(risk, self.cfg.squeal_min_risk), KIND_SQUEAL, "site",
                           np.asarray(stamp_ns), "squeal", self._squeal_what(), full_window=True)

    def on_train_passes(self, stamp_ns: np.ndarray, rejected: np.ndarray) -> list[Alert]:
        """TrainPass messages in order, rejected or not."""
        return self._share(self._rejected, np.asarray(rejected, bool), KIND_INPUT_REJECTED, "train_pass",
                           np.asarray(stamp_ns), "rejected", "train passes rejected", full_window=False)

    def on_residuals(self, residuals: Sequence[Any]) -> list[Alert]:
        """NoiseResiduals in order (those of ``residual_model``; others are passed over): a wheel
        defect suspect per vehicle (or train) with hysteresis, and the drift of the baseline."""
        cfg, events = self.cfg, []
        residuals = [r for r in residuals if r.model == cfg.residual_model]
        for r in residuals:
            score = wheel_defect_score(r, cfg.wheel_defect_vehicle_db)
            named = r.loudest_vehicle_id and r.loudest_vehicle_excess_db >= cfg.wheel_defect_vehicle_db
            key = f"vehicle {r.loudest_vehicle_id}" if named else f"train {r.train_id}"
            if score >= cfg.wheel_defect_raise_db:
                self.offences[key] += 1
                if len(self.offences) > OFFENDERS_KEPT:  # a new train id per pass must not grow it for ever
                    self.offences = Counter(dict(self.offences.most_common(OFFENDERS_KEPT // 2)))
                    self.offences[key] = max(self.offences[key], 1)
                events.append(self._set(
                    True, KIND_WHEEL_DEFECT, key, r.stamp_ns, SEVERITY_WARNING,
                    f"wheel defect suspect: {key} (train {r.train_id}) {score:+.1f} dB over the site's baseline "
                    f"at 500-2000 Hz or its train's mean, flagged {self.offences[key]} time(s)", score,
                    cfg.wheel_defect_raise_db, "dB"))
            elif score < cfg.wheel_defect_clear_db:
                for k in [f"train {r.train_id}", *(f"vehicle {v}" for v in r.vehicle_id)]:
                    if (KIND_WHEEL_DEFECT, k) in self.standing:
                        events.append(self._set(False, KIND_WHEEL_DEFECT, k, r.stamp_ns, SEVERITY_INFO,
                                                f"wheel defect suspect: {k} cleared ({score:+.1f} dB)", score,
                                                cfg.wheel_defect_clear_db, "dB"))
            if r.drift_db >= cfg.drift_raise_db or r.drift_db < cfg.drift_clear_db:
                up = r.drift_db >= cfg.drift_raise_db
                events.append(self._set(
                    up, KIND_NOISE_DRIFT, r.model, r.stamp_ns, SEVERITY_WARNING if up else SEVERITY_INFO,
                    f"{r.model} residual at 500-2000 Hz {r.drift_db:+.1f} dB since its baseline filled: the rail "
                    f"roughens faster than the model says" if up else f"{r.model} residual drift cleared",
                    r.drift_db, cfg.drift_raise_db if up else cfg.drift_clear_db, "dB"))
        if residuals:
            stamps = np.array([r.stamp_ns for r in residuals], np.int64)
            predicted = counts_as_squeal(np.array([r.squeal_risk for r in residuals]), cfg.squeal_min_risk)
            measured = np.array([r.squeal_detected for r in residuals], bool)
            for key, hits in zip(MISMATCHES, (measured & ~predicted, predicted & ~measured), strict=True):
                events += self._share(self._mismatch[key], hits, KIND_SQUEAL_MISMATCH, key, stamps,
                                      "squeal_mismatch", f"squeal {key}", full_window=True)
            events += self._share(self._heard, measured, KIND_SQUEAL_MEASURED, "site", stamps, "squeal_measured",
                                  "squeal measured", full_window=True)
            for r in residuals:
                for v in self.squealers.add(r.stamp_ns, r.train_id, tuple(r.vehicle_id), r.squeal_detected,
                                            r.squeal_risk):
                    events.append(self._set(
                        v.flagged, KIND_SQUEAL_OFFENDER, v.key, v.stamp_ns,
                        SEVERITY_WARNING if v.flagged else SEVERITY_INFO,
                        f"repeat squealer: {v.key} heard squealing on {v.squealed} of its last {v.passes} measured "
                        f"passes, {v.expected:.1f} expected at the site's share for passes alike (chance "
                        f"{v.chance:.1e})" if v.flagged else f"repeat squealer: {v.key} cleared ({v.squealed} of "
                        f"{v.passes}, {v.expected:.1f} expected)", v.chance,
                        cfg.squeal_offender_raise_p if v.flagged else cfg.squeal_offender_clear_p, "-"))
        return [e for e in events if e]

    def on_squeal_fit(self, stamp_ns: int, windows: Sequence[tuple[str, int, int, float, float]]) -> list[Alert]:
        """One fit of the squeal model (a SquealCalibration): per friction state, its window's measured
        passes, those flagged squealing and the predicted share's P10 and P90 [-] (alerts.squeal_drift)."""
        events = [self._set(bool(v.side), KIND_SQUEAL_DRIFT, v.state, stamp_ns,
                            SEVERITY_WARNING if v.side else SEVERITY_INFO, v.summary, v.share,
                            v.p90 if v.side > 0 else v.p10, "-") for v in self.drift.changes(windows)]
        return [e for e in events if e]

MISMATCHES = ("measured, not predicted", "predicted, not measured")  # the squeal-mismatch alerts' keys


def wheel_defect_score(r: Any, vehicle_db: float) -> float:
    """A residual's wheel-defect score [dB]: its 500-2000 Hz excess over the site's baseline, or
    its loudest vehicle's excess over the train's mean where that names a vehicle (at least
    vehicle_db), whichever is larger (NaN without a baseline or a named vehicle)."""
    vehicle = r.loudest_vehicle_excess_db if r.loudest_vehicle_id and r.loudest_vehicle_excess_db >= vehicle_db \
        else float("nan")
    return float(np.fmax(r.excess_mid_db, vehicle))


def describe(alert: Alert) -> str:
    """One line for people: pass time, raised/cleared, kind, summary."""
    verb = "raised " if alert.active else "cleared"
    return f"{format_iso_ns(alert.stamp_ns)}  {verb}  {KIND_NAMES[alert.kind]:17s} {printable(alert.summary)}"
