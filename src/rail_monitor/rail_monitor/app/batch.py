"""Batch mode: the graph's models over a whole pass history without DDS, vectorised (no rclpy).

Gives what the live graph publishes, pass for pass, by calling the same functions with many
passes: the squeal prediction of every accepted pass; the corrugation state after every counted
pass (CorrugationEstimator.advance_history); the rolling noise of every accepted pass on the
corrugation state that includes it (as rolling_noise_predictor waits for it); the alerts of the
alert manager; and the speed advice on the final state. ``write_bag`` records them under the same
topics, types and QoS as mcap_recorder records the live graph.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor.advice.consequences import Consequences
from rail_monitor.advice.plan import SpeedAdvice, advise_or_none
from rail_monitor.alerts.config import alert_config
from rail_monitor.alerts.manager import Alert, AlertManager
from rail_monitor.bagio import messages as fields
from rail_monitor.bagio.cdr import serialize
from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.site_record import SITE_RECORD, custom_data
from rail_monitor.bagio.topics import GRAPH_TOPICS
from rail_monitor.core.node_params import STAMP_SPECS, StampParams
from rail_monitor.core.params import resolve, section, values_of
from rail_monitor.core.passes import PassTable, publishable, reject_ahead, rejection_reasons, with_class_defaults
from rail_monitor.core.site import Site, site_from_values
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Trajectory
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import Corrugation, NoisePrediction, RollingNoiseModel
from rail_monitor.noise.state_of_pass import state_index
from rail_monitor.squeal.config import squeal_config
from rail_monitor.squeal.predict import predict as predict_squeal

HISTORY_CHUNK = 50_000  # passes per advance_history call: bounds its (passes x bands x components) arrays
NOISE_CHUNK = 20_000  # passes per noise prediction: bounds the (passes x time steps) arrays of LpAFmax


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
    noise: dict[str, NoisePrediction]  # per source model
    alerts: list[Alert]
    standing: list[Alert]
    advice: SpeedAdvice | None
    estimator: CorrugationEstimator   # the final state
    receiver: Any
    left_out: dict[str, int]          # passes the replayer would not send, by reason


def run_models(passes: PassTable, values: Mapping[str, Any], estimator: CorrugationEstimator | None = None,
               threads: int = 0) -> BatchResult:
    """Every model over ``passes`` for the site of the flat parameter ``values``.

    estimator: a state to continue from (e.g. a checkpoint); default the post-grinding state.
    threads: threads for the independent parts (squeal beside the corrugation history; the noise
    chunks of every model), 0: one per core. numpy releases the interpreter lock in its array
    loops, so the threads use the cores; the chunks are the same whatever the count, so the
    results are too.
    """
    site = site_from_values(values)
    margins = values_of(StampParams, resolve(STAMP_SPECS, section(values, "stamps."), "stamps.", strict=True))
    table, left_out = publishable(passes, margins)  # what the replayer sends
    reasons = rejection_reasons(table, site)
    est = estimator or CorrugationEstimator(site, corrugation_config(values))
    reject_ahead(table.stamp_ns, reasons, est.newest_ns, margins)  # as every node of the graph does
    accepted = with_class_defaults(table.take(reasons == ""), site)
    model = RollingNoiseModel(site, noise_config(values))
    with ThreadPoolExecutor(max_workers=threads or os.cpu_count() or 1) as pool:
        squeal_job = pool.submit(predict_squeal, squeal_config(values), site, accepted)
        traj = _history(est, accepted)
        state_of_pass = state_index(traj.stamp_ns, traj.train_id.tolist(), accepted.stamp_ns,
                                    accepted.train_id.tolist())
        noise = _noise_on_states(pool, model, accepted, traj, state_of_pass)
        squeal = squeal_job.result()
    alerts = AlertManager(alert_config(values, est.cfg.lead_time_days))
    events = _feed_alerts(alerts, table, reasons, accepted, squeal, traj, noise)
    return BatchResult(site, table, reasons, accepted, squeal, traj, state_of_pass, noise, events,
                       sorted(alerts.standing.values(), key=_alert_key),
                       advise_or_none(est, Consequences(site, model, squeal_config(values))), est, model.receiver,
                       left_out)


def _history(est: CorrugationEstimator, passes: PassTable) -> Trajectory:
    """est.advance_history in chunks of passes (the estimator carries the kept passes from one to
    the next, so the states are those of one call), joined."""
    if len(passes) <= HISTORY_CHUNK:
        return est.advance_history(passes)
    return Trajectory.concat([(i, est.advance_history(passes.take(slice(i, i + HISTORY_CHUNK))))
                              for i in range(0, len(passes), HISTORY_CHUNK)])


def _noise_on_states(pool: ThreadPoolExecutor, model: RollingNoiseModel, accepted: PassTable, traj: Trajectory,
                     state_of_pass: np.ndarray) -> dict[str, NoisePrediction]:
    """Every model's noise of every accepted pass, each on its state (passes before any state on
    none), as tasks of pool."""
    have = state_of_pass >= 0
    c = traj.constants
    on_state = accepted.take(have)
    state = Corrugation(c.bands, traj.amplitude[state_of_pass[have]], c.grinding_amplitude)
    jobs = {name: (_noise_chunks(pool, model, on_state, name, state),
                   None if have.all() else _noise_chunks(pool, model, accepted.take(~have), name))
            for name in model.models}
    out = {}
    for name, (with_state, without) in jobs.items():
        joined = NoisePrediction.concat([f.result() for f in with_state])
        out[name] = joined if without is None else joined.merged(have, NoisePrediction.concat(
            [f.result() for f in without]))
    return out


def _noise_chunks(pool: ThreadPoolExecutor, model: RollingNoiseModel, passes: PassTable, name: str,
                  corrugation: Corrugation | None = None) -> list[Future]:
    """model.predict over chunks of NOISE_CHUNK passes (each pass is independent), one task each."""
    jobs = []
    for i in range(0, max(len(passes), 1), NOISE_CHUNK):
        rows = slice(i, i + NOISE_CHUNK)
        state = corrugation if corrugation is None or corrugation.amplitude_m.ndim == 1 else Corrugation(
            corrugation.wavelength_m, corrugation.amplitude_m[rows], corrugation.post_grinding_m)
        jobs.append(pool.submit(model.predict, passes.take(rows), name, state))
    return jobs


def _alert_key(a: Alert) -> tuple[int, int, str, bool]:
    return a.stamp_ns, a.kind, a.key, a.active


def _feed_alerts(alerts: AlertManager, table: PassTable, reasons: np.ndarray, accepted: PassTable,
                 squeal: dict[str, np.ndarray], traj: Trajectory, noise: dict[str, NoisePrediction]) -> list[Alert]:
    """The alert manager over each stream in its own order (streams do not interact), a stream at once."""
    alerts.on_train_passes(table.stamp_ns, reasons != "")
    alerts.on_squeal(accepted.stamp_ns, squeal["risk"])
    for name, out in noise.items():
        alerts.on_noise(accepted.stamp_ns, name, out.per_pass())
    c, f = traj.constants, traj.forecast
    alerts.on_states(traj.stamp_ns, c.bands, traj.amplitude, c.threshold, f.days_to_threshold, f.grinding_due,
                     f.grinding_due_ns)
    return sorted(alerts.events, key=_alert_key)


# -- recording ----------------------------------------------------------------------------------
def write_bag(result: BatchResult, folder: str | Path, namespace: str, compression: str = "zstd",
              site: dict[str, str] | None = None) -> Path:
    """Record the batch outputs as mcap_recorder records the live graph (log time = header stamp);
    site: the site record stored with the bag (bagio.site_record), as the recorder stores it."""
    ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
    frame = result.site.site_id
    stored = {"records": {SITE_RECORD: site}, "custom_data": custom_data(site)} if site else {}
    with McapBagWriter(Path(folder), compression=compression, **stored) as bag:
        for name, (typename, qos) in GRAPH_TOPICS.items():
            bag.add_topic(f"{ns}/{name}", typename, [qos.as_metadata()])

        def put(name: str, msg: dict[str, Any], stamp_ns: int) -> None:
            bag.write(f"{ns}/{name}", serialize(GRAPH_TOPICS[name][0], msg), stamp_ns)

        sent = [fields.train_pass_fields(result.passes.row(i), frame) for i in range(len(result.passes))]
        by_accepted = [m for m, why in zip(sent, result.reasons, strict=True) if not why]
        for msg, stamp in zip(sent, result.passes.stamp_ns.tolist(), strict=True):
            put("train_pass", msg, max(stamp, 0))  # a log time cannot be before 1970
        for i, msg in enumerate(by_accepted):
            put("noise/squeal", fields.squeal_prediction_fields(result.squeal, i, msg["header"], msg["train_id"]),
                int(result.accepted.stamp_ns[i]))
        for k in range(len(result.trajectory)):
            snap, fc = result.trajectory.state(k)
            put("corrugation/state", fields.corrugation_state_fields(snap, fc, frame), snap.newest_ns)
        for i, msg in enumerate(by_accepted):
            for out in result.noise.values():
                put("noise/rolling", fields.rolling_noise_fields(out, i, msg["header"], msg["train_id"],
                                                                 result.receiver), int(result.accepted.stamp_ns[i]))
        standing: dict[tuple[int, str], Alert] = {}
        for a in result.alerts:
            put("alerts", fields.wayside_alert_fields(a, frame), a.stamp_ns)
            if a.active:
                standing[(a.kind, a.key)] = a
            else:
                standing.pop((a.kind, a.key), None)
            put("alerts/standing", fields.wayside_alert_array_fields(list(standing.values()), a.stamp_ns, frame),
                a.stamp_ns)
        if result.advice is not None:
            stamp = result.estimator.newest_ns
            put("speed_advisory", fields.speed_advisory_fields(result.advice, stamp, frame), stamp)
    return Path(folder)
