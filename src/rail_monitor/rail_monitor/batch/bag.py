"""Recording batch outputs as mcap_recorder records the live graph: the same topics, types and QoS,
log time = header stamp; chunk by chunk, so a long history is never held whole (no rclpy)."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rail_monitor.advice.plan import SpeedAdvice
from rail_monitor.alerts.manager import Alert
from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.output_folder import Claim, claim_output_folder
from rail_monitor.bagio.site_record import SITE_RECORD, custom_data
from rail_monitor.codec.cdr_from_columns import serialize_columns
from rail_monitor.core.errors import PassOrderError
from rail_monitor.core.friction import ApplicatorEvent
from rail_monitor.core.passes import PassTable
from rail_monitor.core.text import printable
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.engine.result import SiteOutputs
from rail_monitor.engine.site import SiteEngine
from rail_monitor.measured.records import Measurement
from rail_monitor.measured.residuals import Residual
from rail_monitor.messages import event_fields, fields, outputs
from rail_monitor.messages.topics import GRAPH_TOPICS, OPTIONAL_TOPICS


class BatchBag:
    """A bag folder taking SiteEngine's results one chunk at a time (``add``), then the held-back
    events and the advice (``finish``). site: the site record stored with the bag
    (bagio.site_record), as the recorder stores it."""

    def __init__(self, folder: str | Path, namespace: str, frame: str, compression: str = "zstd",
                 site: dict[str, str] | None = None, claim: Claim | None = None) -> None:
        self.ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
        self.frame = frame
        stored = {"records": {SITE_RECORD: site}, "custom_data": custom_data(site)} if site else {}
        self.bag = McapBagWriter(Path(folder), compression=compression, claim=claim, **stored)
        for name, (typename, qos) in GRAPH_TOPICS.items():
            self.bag.add_topic(f"{self.ns}/{name}", typename, [qos.as_metadata()])
        self._alert_stream = outputs.AlertStream(frame)

    def __enter__(self) -> BatchBag:
        return self

    def __exit__(self, *exc: object) -> None:
        self.bag.close()

    def _put(self, name: str, msg: dict[str, Any], stamp_ns: int) -> None:
        self._write(outputs.one(name, msg, stamp_ns))

    def _write(self, messages: outputs.Messages) -> None:
        """Messages of a graph topic, in order, logged at their stamps (none before 1970); an optional
        topic is declared with its first message, as the recorder records it once it is published."""
        name = messages.topic
        if name not in GRAPH_TOPICS:
            typename, qos = OPTIONAL_TOPICS[name]
            self.bag.add_topic(f"{self.ns}/{name}", typename, [qos.as_metadata()])
        self.bag.write_many(f"{self.ns}/{name}", messages.datas, [max(t, 0) for t in messages.stamps_ns])

    def events(self, events: list[MaintenanceEvent]) -> None:
        """Surveys and grinding events given to the run, on the topic the replayer sends them on."""
        for event in events:
            self._put("roughness_survey", event_fields.roughness_survey_fields(event, self.frame), event.stamp_ns)

    def applicators(self, events: Sequence[ApplicatorEvent]) -> None:
        """A friction-modifier applicator's starts and stops, on the topic the replayer sends them on
        (the models do not take them; the report does)."""
        for e in events:
            self._put("friction_applicator", event_fields.friction_applicator_fields(e, self.frame), e.stamp_ns)

    def measured(self, measurements: list[Measurement], residuals: list[Residual]) -> None:
        """Measurements given to the run (as the replayer sends them) and the residuals computed."""
        for m in measurements:
            self._put("noise/measured", fields.measured_pass_noise_fields(m, self.frame), m.stamp_ns)
        for msgs in outputs.measured(residuals, (), self.frame):
            self._write(msgs)

    def add(self, result: SiteOutputs) -> None:
        """One chunk's passes and outputs, and its settled alert events."""
        passes = result.passes
        datas = serialize_columns(GRAPH_TOPICS["train_pass"][0], fields.train_pass_columns(passes, self.frame),
                                  len(passes))
        self._write(outputs.Messages("train_pass", datas, passes.stamp_ns.tolist()))
        for msgs in outputs.per_pass(result, self.frame):
            self._write(msgs)
        self._alerts(result.alerts)
        self.events(result.events)
        self.measured(result.measurements, result.residuals)
        for msgs in outputs.measured((), result.observations, self.frame, result.calibrations):
            self._write(msgs)
        if result.outlooks:
            self._write(outputs.outlooks(result.outlooks, self.frame))

    def _alerts(self, events: list[Alert]) -> None:
        for msgs in self._alert_stream.messages(events):
            self._write(msgs)

    def finish(self, held: list[Alert], advice: SpeedAdvice | None, newest_ns: int) -> None:
        """The events held back for a later chunk and the advice on the final state (stamped with its
        newest pass)."""
        self._alerts(held)
        if advice is not None:
            self._write(outputs.advice(advice, newest_ns, self.frame))


def write_bag(result: SiteOutputs, folder: str | Path, namespace: str, compression: str = "zstd",
              site: dict[str, str] | None = None, applicators: Sequence[ApplicatorEvent] = ()) -> Path:
    """Record a whole history's outputs (run_models) in a new bag folder, with the history's
    applicator starts and stops."""
    with BatchBag(folder, namespace, result.site.site_id, compression, site) as bag:
        bag.applicators(applicators)
        bag.add(result)  # its events include those after the last pass (run_models)
        bag.finish([], result.advice, result.estimator.newest_ns)
    return Path(folder)


@dataclass
class Recorded:
    """What a batch run recorded: passes recorded and read, rejected, alert events, the final forecast [day]
    (inf: none), passes left out by reason, and lines for the user (what was skipped or salvaged)."""

    passes: int = 0                                               # passes recorded (sent to the models)
    read: int = 0                                                 # passes read (recorded or left out)
    rejected: int = 0
    alert_events: int = 0
    days_to_threshold: float = math.inf
    left_out: dict[str, int] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    events: int = 0                                               # surveys and grinding events read
    events_applied: int = 0                                       # of those, applied
    events_refused: dict[str, int] = field(default_factory=dict)  # of those, refused by reason
    measurements: int = 0                                         # measured pass-bys read
    measurements_refused: dict[str, int] = field(default_factory=dict)


def run_to_bag(chunks: Iterable[PassTable], values: Mapping[str, Any], folder: str | Path, namespace: str,
               site: dict[str, str] | None = None, events: Sequence[MaintenanceEvent] = (),
               measurements: Sequence[Measurement] = (), claim: Claim | None = None,
               applicators: Sequence[ApplicatorEvent] = ()) -> Recorded:
    """SiteEngine over an iterable of PassTable chunks in time order (and the history's surveys and
    grinding events, and its measured pass-bys), each recorded as it is done (memory: one chunk's
    outputs), with the history's applicator starts and stops. claim: the folder, claimed already
    (else claimed here)."""
    run = SiteEngine(values, events=events, measurements=measurements)
    out = Recorded()
    with BatchBag(folder, namespace, run.site.site_id, site=site, claim=claim) as bag:
        bag.applicators(applicators)
        for chunk in chunks:
            result = run.feed(chunk)
            bag.add(result)
            out.read += len(chunk)
            out.passes += len(result.passes)
            out.rejected += int((result.reasons != "").sum())
            out.alert_events += len(result.alerts)
            if len(result.trajectory):
                out.days_to_threshold = float(result.trajectory.forecast.days_to_threshold[-1])
        held, advice = run.finish()
        bag.events(run.trailing_events)
        bag.measured(run.trailing_measurements, [])
        bag.finish(held, advice, run.estimator.newest_ns)
    out.alert_events += len(held)
    out.left_out = dict(run.left_out)
    out.events, out.events_refused = len(events), dict(run.events_refused)
    out.events_applied = run.corrugation.maintenance_applied
    out.measurements, out.measurements_refused = len(measurements), dict(run.tracker.refused)
    return out


def record_history(source: str | Path, values: Mapping[str, Any], folder: Path, namespace: str,
                   site: dict[str, str] | None = None, topic: str | None = None, chunk: int = 5_000,
                   skip_bad_rows: bool = False, salvage: bool = False, measured: str | Path | None = None,
                   surveys: Sequence[str | Path] = ()) -> Recorded:
    """The batch run of a history file recorded to a new bag folder. A bag is read and recorded chunk
    by chunk (memory flat in its length); a CSV, a salvaged bag, or a bag whose passes are not in
    time order is read whole and sorted. Its measured pass-bys are measured's (a noise station's
    CSV or a bag), else a bag history's own; its surveys and grinding events the history bag's own
    with those of the bags ``surveys``; its applicator starts and stops the history bag's own. A run
    that fails leaves no output behind."""
    from rail_monitor.bagio.reader import is_csv, iter_bag_passes, read_applicators, read_history_inputs

    claim = claim_output_folder(folder)  # atomic: two runs never write one folder
    try:
        events, ms = read_history_inputs(source, measured, skip_bad_rows, salvage, surveys)
        applicators, refused = read_applicators(source, salvage)
        notes = [f"{n} friction applicator event(s) of {printable(str(source))} left out: {why}"
                 for why, n in sorted(refused.items())]
        if not (salvage or is_csv(Path(source))):
            try:
                rec = run_to_bag(iter_bag_passes(source, topic, chunk), values, folder, namespace, site, events, ms,
                                 claim, applicators)
                rec.notes[:0] = notes
                return rec
            except PassOrderError as exc:
                notes.insert(0, f"{printable(str(source))}: {exc}; read whole to sort it")
                claim.empty()
        rec = _whole(source, values, claim, namespace, site, topic, skip_bad_rows, salvage, events, ms, applicators)
        rec.notes[:0] = notes
        return rec
    except BaseException:
        claim.release()  # what this run claimed and wrote, proven by its claim; nothing else
        raise


def _whole(source: str | Path, values: Mapping[str, Any], claim: Claim, namespace: str,
           site: dict[str, str] | None, topic: str | None, skip_bad_rows: bool, salvage: bool,
           events: list[MaintenanceEvent], measured: list[Measurement],
           applicators: Sequence[ApplicatorEvent]) -> Recorded:
    from rail_monitor.bagio.reader import read_passes_reported

    passes, report = read_passes_reported(source, topic, skip_bad_rows=skip_bad_rows, salvage=salvage)
    notes = [printable(report.salvage.line(source)), "surveys, grinding and the bag's measured noise are not "
             "salvaged"] if report.salvage is not None else []
    skipped = report.skipped_rows
    if skipped:
        notes.append(f"{len(skipped)} malformed row(s) of {printable(str(source))} left out: "
                     + "; ".join(printable(s) for s in skipped[:5]) + ("; ..." if len(skipped) > 5 else ""))
    rec = run_to_bag([passes], values, claim.folder, namespace, site, events, measured, claim, applicators)
    rec.notes = notes
    return rec
