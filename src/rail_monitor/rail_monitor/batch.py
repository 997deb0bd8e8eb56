"""Batch mode: the graph's models over a whole pass history without DDS, vectorised.

Gives what the live graph publishes, pass for pass: the squeal prediction of every accepted
pass; the corrugation state after every counted pass (CorrugationEstimator.advance_history);
the rolling noise of every accepted pass on the corrugation state that includes it (as
rolling_noise_predictor waits for it); the alerts of the alert manager; and the speed advice on
the final state. ``write_bag`` records them under the same topics as mcap_recorder.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor.alerts import Alert, AlertManager, alert_config
from rail_monitor.corrugation_state import Advice, CorrugationEstimator, Forecast, Trajectory, corrugation_config
from rail_monitor.passes import PassTable, rejection_reasons, with_class_defaults
from rail_monitor.rolling_noise import Corrugation, RollingNoiseModel, noise_config
from rail_monitor.site import Site, site_from_values
from rail_monitor.squeal_risk import predict as predict_squeal
from rail_monitor.squeal_risk import squeal_config


@dataclass
class BatchResult:
    """Model outputs over a history. Arrays over ``accepted`` rows unless named otherwise."""

    site: Site
    passes: PassTable                 # the whole history in time order (as the replayer sends it)
    reasons: np.ndarray               # per pass: '' accepted, else why rejected
    accepted: PassTable               # accepted passes, class defaults filled
    squeal: dict[str, np.ndarray]
    trajectory: Trajectory            # state after each counted pass (index: row of ``accepted``)
    state_of_pass: np.ndarray         # per accepted pass: trajectory row it was predicted on (-1: none)
    noise: dict[str, dict[str, Any]]  # per source model
    alerts: list[Alert]
    standing: list[Alert]
    advice: Advice | None
    estimator: CorrugationEstimator   # the final state
    receiver: Any


def run_models(passes: PassTable, values: Mapping[str, Any], estimator: CorrugationEstimator | None = None
               ) -> BatchResult:
    """Every model over ``passes`` for the site of the flat parameter ``values``.

    estimator: a state to continue from (e.g. a checkpoint); default the post-grinding state.
    """
    site = site_from_values(values)
    table = passes.sorted()
    reasons = rejection_reasons(table, site)
    ok = reasons == ""
    accepted = with_class_defaults(table.take(ok), site)
    est = estimator or CorrugationEstimator(site, corrugation_config(values))
    squeal = predict_squeal(squeal_config(values), site, accepted)
    traj = _history(est, accepted)
    # A pass is predicted on the state that includes it, or for a pass not counted the latest before it.
    state_of_pass = np.searchsorted(traj.index, np.arange(len(accepted)), side="right") - 1
    model = RollingNoiseModel(site, noise_config(values))
    noise: dict[str, dict[str, Any]] = {}
    have = state_of_pass >= 0
    for name in model.models:
        out = _predict_noise(model, accepted.take(~have), name) if (~have).any() else None
        with_state = _predict_noise(model, accepted.take(have), name, Corrugation(
            traj.constants.bands, traj.amplitude[state_of_pass[have]], traj.constants.grinding_amplitude))
        noise[name] = _merge(with_state, out, have)
    alerts = AlertManager(alert_config(values, est.cfg["lead_time_days"]))
    events = _feed_alerts(alerts, table, reasons, accepted, squeal, traj, noise)
    advice = None
    if len(est.recent.stamp_ns):
        try:
            advice = est.advise()
        except ValueError:
            advice = None
    return BatchResult(site, table, reasons, accepted, squeal, traj, state_of_pass, noise, events,
                       sorted(alerts.standing.values(), key=_alert_key), advice, est, model.receiver)


HISTORY_CHUNK = 50_000  # passes per advance_history call: bounds its (passes x bands x components) arrays
NOISE_CHUNK = 20_000  # passes per noise prediction: bounds the (passes x time steps) arrays of LpAFmax


def _history(est: CorrugationEstimator, passes: PassTable) -> Trajectory:
    """est.advance_history in chunks of passes (the estimator carries the kept passes from one to
    the next, so the states are those of one call), joined."""
    if len(passes) <= HISTORY_CHUNK:
        return est.advance_history(passes)
    parts = [(i, est.advance_history(passes.take(slice(i, i + HISTORY_CHUNK))))
             for i in range(0, len(passes), HISTORY_CHUNK)]
    first = parts[0][1]

    def join(get: Any) -> np.ndarray:
        return np.concatenate([get(t) for _, t in parts])

    f = Forecast(**{k: join(lambda t, k=k: getattr(t.forecast, k)) for k in vars(first.forecast)})
    return Trajectory(index=np.concatenate([t.index + i for i, t in parts]), stamp_ns=join(lambda t: t.stamp_ns),
                      train_id=join(lambda t: t.train_id), amplitude=join(lambda t: t.amplitude),
                      pass_count=join(lambda t: t.pass_count), axle_pass_count=join(lambda t: t.axle_pass_count),
                      total_pass_count=join(lambda t: t.total_pass_count), forecast=f, constants=first.constants)


def _predict_noise(model: RollingNoiseModel, passes: PassTable, name: str,
                   corrugation: Corrugation | None = None) -> dict[str, Any]:
    """model.predict in chunks of passes (each pass is independent), joined in order."""
    if len(passes) <= NOISE_CHUNK:
        return model.predict(passes, name, corrugation)
    parts = []
    for i in range(0, len(passes), NOISE_CHUNK):
        rows = slice(i, i + NOISE_CHUNK)
        state = corrugation if corrugation is None or corrugation.amplitude_m.ndim == 1 else Corrugation(
            corrugation.wavelength_m, corrugation.amplitude_m[rows], corrugation.post_grinding_m)
        parts.append(model.predict(passes.take(rows), name, state))
    out = dict(parts[0])
    for key, value in out.items():
        if _per_pass(key, value, len(parts[0]["speed_mps"])):
            out[key] = np.concatenate([p[key] for p in parts])
    return out


def _per_pass(key: str, value: Any, n: int) -> bool:
    """Whether a prediction's field is an array over passes (not the band centres)."""
    return isinstance(value, np.ndarray) and value.ndim > 0 and len(value) == n and key != "band_centre_hz"


def _merge(with_state: dict[str, Any], without: dict[str, Any] | None, have: np.ndarray) -> dict[str, Any]:
    """Rows predicted with a state and without one, back in pass order."""
    if without is None:
        return with_state
    out = dict(with_state)
    for key, value in with_state.items():
        if _per_pass(key, value, int(have.sum())):
            merged = np.empty((len(have), *value.shape[1:]), value.dtype)
            merged[have], merged[~have] = value, without[key]
            out[key] = merged
    return out


def _alert_key(a: Alert) -> tuple[int, int, str, bool]:
    return a.stamp_ns, a.kind, a.key, a.active


def _feed_alerts(alerts: AlertManager, table: PassTable, reasons: np.ndarray, accepted: PassTable,
                 squeal: dict[str, np.ndarray], traj: Trajectory, noise: dict[str, dict[str, Any]]) -> list[Alert]:
    """The alert manager over each stream in its own order (streams do not interact), a stream at once."""
    alerts.on_train_pass_series(table.stamp_ns, reasons != "")
    alerts.on_squeal_series(accepted.stamp_ns, squeal["risk"])
    for name, out in noise.items():
        alerts.on_noise_series(accepted.stamp_ns, name, out)
    c, f = traj.constants, traj.forecast
    alerts.on_states(traj.stamp_ns, c.bands, traj.amplitude, c.threshold, f.days_to_threshold, f.grinding_due,
                     f.grinding_due_ns)
    return sorted(alerts.events, key=_alert_key)


# -- recording ----------------------------------------------------------------------------------
def write_bag(result: BatchResult, folder: str | Path, namespace: str, compression: str = "zstd") -> Path:
    """Record the batch outputs as mcap_recorder records the live graph (log time = header stamp)."""
    from rclpy.serialization import serialize_message

    from rail_monitor.bagio.mcap_bag import McapBagWriter
    from rail_monitor.nodes import convert
    from rail_monitor.nodes.qos import qos_to_dict

    ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
    frame = result.site.site_id
    with McapBagWriter(Path(folder), compression=compression) as bag:
        for name, (msg_type, qos) in convert.GRAPH_TOPICS.items():
            bag.add_topic(f"{ns}/{name}", convert.typename(msg_type), [qos_to_dict(qos)])

        def put(name: str, msg: Any, stamp_ns: int) -> None:
            bag.write(f"{ns}/{name}", serialize_message(msg), stamp_ns)

        sent = [convert.train_pass_msg(result.passes.row(i), frame) for i in range(len(result.passes))]
        by_accepted = [m for m, why in zip(sent, result.reasons, strict=True) if not why]
        for msg, stamp in zip(sent, result.passes.stamp_ns.tolist(), strict=True):
            put("train_pass", msg, stamp)
        for i, msg in enumerate(by_accepted):
            put("noise/squeal", convert.squeal_prediction_msg(result.squeal, i, msg), int(result.accepted.stamp_ns[i]))
        for k in range(len(result.trajectory)):
            snap, fc = result.trajectory.state(k)
            put("corrugation/state", convert.corrugation_state_msg(snap, fc, frame), snap.newest_ns)
        for i, msg in enumerate(by_accepted):
            for out in result.noise.values():
                put("noise/rolling", convert.rolling_noise_msg(out, i, msg, result.receiver),
                    int(result.accepted.stamp_ns[i]))
        standing: dict[tuple[int, str], Alert] = {}
        for a in result.alerts:
            put("alerts", convert.wayside_alert_msg(a, frame), a.stamp_ns)
            if a.active:
                standing[(a.kind, a.key)] = a
            else:
                standing.pop((a.kind, a.key), None)
            put("alerts/standing", convert.wayside_alert_array_msg(list(standing.values()), a.stamp_ns, frame),
                a.stamp_ns)
        if result.advice is not None:
            stamp = result.estimator.newest_ns
            put("speed_advisory", convert.speed_advisory_msg(result.advice, stamp, frame), stamp)
    return Path(folder)

