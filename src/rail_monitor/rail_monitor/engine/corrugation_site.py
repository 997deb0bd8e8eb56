"""The corrugation part of a site's engine: the state, its surveys and grinding, and the indirect
roughness windows, taken in stamp order (no rclpy).

Batch mode, the corrugation_estimator node and the what-if share this one step, so they apply the
same events before the same passes by construction:

- a survey or grinding applies to the state after every pass stamped at or before it, and before
  the first pass stamped later (:func:`rail_monitor.corrugation.surveys.split_before`);
- with ``residual.indirect_days`` > 0 the open window of measured pass-bys is closed before the
  first pass stamped after its end, and its indirect roughness is taken as a survey
  (:mod:`rail_monitor.measured.observer`); an event and a window's end on the same pass: the event
  first (:func:`rail_monitor.measured.observer.next_cut`).

The owner feeds passes through :meth:`CorrugationSite.segments`, handling each segment (counting
it, predicting on it, publishing) before the cut that follows it is applied; what was applied,
refused and observed is reported through the hooks ``on_event`` and ``on_observation``. With an
``outlook`` maker, each event applied while passes are taken makes the site's grinding outlook
(economics.outlook), kept in ``outlooks`` until the owner takes them (before on_event is called);
the events applied by :meth:`CorrugationSite.finish` make none: they come at the end of a history
or at shutdown, with nobody left to plan on them (the state, checkpointed, holds them).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator, Sequence

from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Trajectory
from rail_monitor.corrugation.surveys import KIND_GRINDING, KIND_INDIRECT, MaintenanceEvent, apply_event, in_time_order
from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.measured.observer import IndirectObserver, Observation, next_cut
from rail_monitor.models.calibration import KbPosterior

EVENT_COUNT = {KIND_GRINDING: "grindings", KIND_INDIRECT: "indirect observations"}  # else "surveys"


def _no_event(event: MaintenanceEvent, fit: KbPosterior | None, why: str) -> None:
    """The default on_event hook: nothing besides the counts."""


def _no_observation(obs: Observation) -> None:
    """The default on_observation hook."""


class CorrugationSite:
    """A site's corrugation state with its pending surveys and grinding and its indirect observer.

    est: the state; observer: the indirect roughness windows (None without them); ahead: a check
    of an event's stamp at the moment it is applied (why it is refused, '' to apply it; None: no
    check, the owner checked it on arrival).
    """

    def __init__(self, est: CorrugationEstimator, observer: IndirectObserver | None = None,
                 ahead: Callable[[int], str] | None = None) -> None:
        self.est = est
        self.observer = observer
        self.ahead = ahead
        self.pending: list[MaintenanceEvent] = []  # surveys and grinding waiting for a later pass, by stamp
        self.refused: Counter[str] = Counter()     # events refused, by reason (each changed nothing)
        self.applied: Counter[str] = Counter()     # events applied, by kind ("surveys", "grindings", ...)
        self.late = 0                              # events taken after passes later than them were counted
        self.on_event: Callable[[MaintenanceEvent, KbPosterior | None, str], None] = _no_event
        self.on_observation: Callable[[Observation], None] = _no_observation
        self.outlook: Callable[[], SiteOutlook] | None = None
        self.outlooks: list[tuple[MaintenanceEvent, SiteOutlook]] = []  # made, not yet taken
        self._finishing = False

    def advance(self, passes: PassTable) -> Trajectory:
        """Count the passes (valid, class defaults filled, no event due among them): the state and
        forecast after each counted pass, also given to the observer's windows."""
        traj = self.est.advance_history(passes)
        if self.observer is not None:
            self.observer.add_counted(passes, traj)
        return traj

    def segments(self, passes: PassTable) -> Iterator[PassTable]:
        """passes (in stream order) cut before each pending event and each window's end. The cut
        after a segment is applied when the owner asks for the next one, so the owner handles a
        segment on the state before the cut (the last segment may be empty of passes only when
        passes is)."""
        start = 0
        while (cut := next_cut(passes.stamp_ns[start:], self.pending, self.observer)) is not None:
            n, window = cut
            yield passes.take(slice(start, start + n))
            if window:
                self.observe()
            else:
                self.apply(self.pending.pop(0))
            start += n
        yield passes.take(slice(start, None)) if start else passes

    def observe(self) -> Observation | None:
        """Close the open indirect roughness window (reported first), then take its observation as
        a survey."""
        obs = self.observer.observe(self.est)
        if obs is None:
            return None
        self.on_observation(obs)
        if obs.event is not None:
            self.apply(obs.event)
        return obs

    def apply(self, event: MaintenanceEvent) -> bool:
        """Apply a survey, grinding or indirect observation now; whether it was applied (a refused
        one is counted by reason and changes nothing)."""
        why = self.ahead(event.stamp_ns) if self.ahead is not None else ""
        fit = None
        if not why:
            try:
                fit = apply_event(self.est, event)
            except ValueError as exc:
                why = str(exc)
        if why:
            self.refuse(event, why)
            return False
        if self.observer is not None:
            self.observer.note(event)
        self.applied[EVENT_COUNT.get(event.kind, "surveys")] += 1
        if self.outlook is not None and not self._finishing:
            self.outlooks.append((event, self.outlook()))
        self.on_event(event, fit, "")
        return True

    def take(self, event: MaintenanceEvent, why: str = "") -> bool:
        """A survey or grinding arriving while passes are taken (live): one stamped at or after the
        newest counted pass waits for the first pass stamped later; an older one is applied at once
        and counted in ``late``; why: a reason found on arrival to refuse it. Whether it was
        applied now."""
        if not why and event.stamp_ns <= max([self.est.last_survey_ns, *(e.stamp_ns for e in self.pending)]):
            why = "not newer than the last survey or grinding applied"
        if why:
            self.refuse(event, why)
            return False
        if event.stamp_ns >= self.est.newest_ns:
            self.pending.append(event)  # stamps rise (checked above)
            return False
        self.late += 1
        return self.apply(event)

    def refuse(self, event: MaintenanceEvent, why: str) -> None:
        """Count a refused event by reason and report it (it changes nothing)."""
        self.refused[why] += 1
        self.on_event(event, None, why)

    @property
    def maintenance_applied(self) -> int:
        """Surveys and grinding events applied (indirect observations aside)."""
        return self.applied["surveys"] + self.applied["grindings"]

    def finish(self) -> list[MaintenanceEvent]:
        """Apply the events later than every pass (at the end of a history, or at shutdown); those
        events, applied or not."""
        rest, self.pending = self.pending, []
        self._finishing = True
        try:
            for event in rest:
                self.apply(event)
        finally:
            self._finishing = False
        return rest

    def take_outlooks(self) -> list[tuple[MaintenanceEvent, SiteOutlook]]:
        """The outlooks made since the last take, with their events."""
        made, self.outlooks = self.outlooks, []
        return made


def advance_with_events(est: CorrugationEstimator, passes: PassTable, events: Sequence[MaintenanceEvent],
                        outlook: Callable[[], SiteOutlook] | None = None) -> CorrugationSite:
    """Advance est over passes (valid, class defaults filled, in stream order) with each event
    applied before the first pass stamped later than it (those after every pass at the end), as
    the engine applies them; the step, with the events refused by reason (``refused``: a refused
    event changes nothing) and, given an outlook maker, the outlooks made (``outlooks``)."""
    site = CorrugationSite(est)
    site.pending = in_time_order(events)
    site.outlook = outlook
    for part in site.segments(passes):
        est.advance(part)
    site.finish()
    return site
