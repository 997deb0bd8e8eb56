"""The squeal model as the site calibrates it (no rclpy): measured pass-bys, paired with their
passes, re-fit each friction state's creep curve (rail_monitor.squeal.calibration), and the passes
after each fit are predicted on its P50 curves.

With ``squeal.fit_days`` = w > 0, time is cut into windows of w days, (k w, (k + 1) w] from the Unix
epoch (UTC), the same in every process. The measured passes paired since the last fit join the fit
before the first accepted pass stamped after a window's end: each state keeps its newest
``squeal.fit_window_passes`` measured passes, its grid follows its posterior's mass, and its P50
k1 and k2 become the curve the squeal model uses from that pass on (the configured curve, the
prior's centre, until the state's first fit). Each fit is a :class:`Calibration`, published and
recorded. The site engine and the squeal_risk_model node hold one each and cut their passes here,
so both predict every pass on the same curves.

A measurement is paired with its accepted pass whichever comes first (live, the pass; in batch,
the measurements are known first): it waits while its stamp is later than every accepted pass
(``residual.held_predictions`` of them at most), a pass among the newest ``residual.held_predictions``
(and up to an eighth more). One whose squeal measures are not
measures (``squeal_observation_refusal``), or whose pass never came, is counted by reason. It must
arrive before the first pass after its window's end (a replay sends each after its pass and
before the next); one that comes later joins the next fit. The curves do not change the advice's
squeal limit, which weighs the configured curves.
"""

from __future__ import annotations

import heapq
from collections import Counter, OrderedDict, deque
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, replace

import numpy as np

from rail_monitor.core.friction import FRICTION_NAMES
from rail_monitor.core.passes import PassTable
from rail_monitor.core.site import Site
from rail_monitor.core.timeutil import NS_PER_DAY, window_end_ns
from rail_monitor.corrugation.surveys import split_before
from rail_monitor.measured.records import Measurement, squeal_observation_refusal
from rail_monitor.squeal.calibration import CurveQuantiles, SquealFit, fit_config
from rail_monitor.squeal.config import SquealConfig
from rail_monitor.squeal.share_check import ShareCheck

PREFIX = "squeal_fit_"  # its checkpoint records
MERGE_TABLES = 64       # held tables not yet indexed, merged into one past this many


@dataclass(frozen=True)
class Calibration:
    """One fit: at stamp_ns (the window's end), per friction state fitted so far, the configured
    curve (k1, k2) [-], the posterior's quantiles, and the window's measured share with the share
    the model predicted before the fit took it (None: no passes of the state in the window)."""

    stamp_ns: int
    states: tuple[tuple[int, tuple[float, float], CurveQuantiles, ShareCheck | None], ...]

    def share_windows(self) -> list[tuple[str, int, int, float, float]]:
        """Per state with passes in the window: its name, the passes, those flagged squealing, and the
        predicted share's P10 and P90 [-] (what the squeal-drift alert judges)."""
        return [(FRICTION_NAMES[code], w.passes, w.squealed, w.predicted[0], w.predicted[2])
                for code, _, _, w in self.states if w is not None]


class SquealSite:
    """The squeal model's site (``site``: the configured one, its creep curves replaced by each fit's
    P50) and the fit behind it. held: passes kept for their measurements still to come."""

    def __init__(self, site: Site, cfg: SquealConfig, min_risk: int, held: int) -> None:
        self.configured = self.site = site
        self.interval_ns = round(cfg.fit_days * NS_PER_DAY)
        self.window = cfg.fit_window_passes
        self.fit = SquealFit(site, cfg, fit_config(cfg, min_risk)) if self.interval_ns > 0 else None
        self.held_max = held
        self.waiting_max = held  # measurements ahead of every accepted pass (a history's own: expect())
        self.window_end_ns = 0                          # end of the open window (0: none yet)
        # Accepted passes awaiting their measurement, oldest first: (stamp, train id) -> (table, row);
        # newer ones in the tables not yet indexed (indexed when a measurement is looked up: a history
        # without measurements costs no work per pass).
        self.held: OrderedDict[tuple[int, str], tuple[PassTable, int]] = OrderedDict()
        self._unindexed: deque[PassTable] = deque()
        self._unindexed_rows = 0
        self.waiting: dict[tuple[int, str], Measurement] = {}  # measurements later than every accepted pass
        self._waiting_order: list[tuple[int, str]] = []  # their keys, a heap (paired ones left in it)
        # Paired since the last fit: (key, its pass, squeal flagged, tone level [dB], microphone distance [m]).
        self.pending: list[tuple[tuple[int, str], PassTable, bool, float, float]] = []
        self.newest_held_ns = np.iinfo(np.int64).min    # the newest accepted pass
        self.newest_taken_ns = -1                       # stamp of the newest measured pass paired
        self.calibrations: list[Calibration] = []       # fits made, until the owner takes them
        self.counts: Counter[str] = Counter()

    @property
    def enabled(self) -> bool:
        return self.fit is not None

    def segments(self, accepted: PassTable) -> Iterator[PassTable]:
        """Accepted passes (in stream order) cut before the first one after each window's end; the
        fit of the window is made when the owner asks for the next segment, so the owner predicts a
        segment on the curves before it (and holds its passes, :meth:`hold`)."""
        start = 0
        while self.enabled and start < len(accepted):
            stamps = accepted.stamp_ns[start:]
            if not self.window_end_ns:
                self.window_end_ns = window_end_ns(int(stamps[0]), self.interval_ns)
            n = split_before(stamps, self.window_end_ns)
            if n == len(stamps):
                break
            yield accepted.take(slice(start, start + n))
            self.refit(self.window_end_ns)
            self.window_end_ns = window_end_ns(int(stamps[n]), self.interval_ns)
            start += n
        yield accepted.take(slice(start, None)) if start else accepted

    def hold(self, accepted: PassTable) -> None:
        """Accepted passes (class defaults filled) predicted: paired with their waiting
        measurements, else held for those still to come."""
        if not self.enabled or not len(accepted):
            return
        if self.waiting:
            self._index()
            for i, key in enumerate(zip(accepted.stamp_ns.tolist(), accepted.train_id.tolist(), strict=True)):
                m = self.waiting.pop(key, None)
                if m is not None:
                    self._pair(key, accepted.take(slice(i, i + 1)), m)
                else:
                    self.held[key] = (accepted, i)
        else:
            self._unindexed.append(accepted)
            self._unindexed_rows += len(accepted)
            if len(self._unindexed) > MERGE_TABLES:  # live: a table a pass; kept as few (cheap to copy out)
                self._unindexed = deque([PassTable.concat(list(self._unindexed))])
        excess = len(self.held) + self._unindexed_rows - self.held_max  # the oldest beyond held_max go
        if excess <= 0 or (not self.held and excess < self.held_max // 8):
            excess = 0  # a merged table is cut once an eighth of it is over, not a pass at a time
        while excess > 0 and self.held:
            self.held.popitem(last=False)
            excess -= 1
        while excess > 0:
            oldest = self._unindexed.popleft()
            if len(oldest) > excess:
                self._unindexed.appendleft(oldest.take(slice(excess, None)))
            self._unindexed_rows -= min(len(oldest), excess)
            excess -= len(oldest)
        self.newest_held_ns = max(self.newest_held_ns, int(accepted.stamp_ns.max()))
        while self._waiting_order and self._waiting_order[0][0] < self.newest_held_ns:  # passes that never came
            if self.waiting.pop(heapq.heappop(self._waiting_order), None) is not None:
                self.counts["no accepted pass (unknown, rejected, or measured twice)"] += 1

    def expect(self, measurements: Sequence[Measurement]) -> None:
        """A history's measurements, known before its passes (batch): all of them may wait."""
        self.waiting_max = max(self.waiting_max, len(measurements))
        self.take(measurements)

    def take(self, measurements: Sequence[Measurement]) -> None:
        """Measured pass-bys: paired with their held passes, or waiting for them; one whose squeal
        measures are not measures, or whose pass is neither held nor to come, is counted by reason."""
        if not self.enabled:
            return
        self._index()
        for m in measurements:
            why = squeal_observation_refusal(m)
            held = self.held.pop(m.key, None) if not why else None
            if why:
                self.counts[f"refused: {why}"] += 1
            elif held is not None:
                self._pair(m.key, held[0].take(slice(held[1], held[1] + 1)), m)
            elif m.stamp_ns >= self.newest_held_ns and m.key not in self.waiting:
                if len(self.waiting) >= self.waiting_max:
                    self.counts["refused: more measurements ahead of every accepted pass than held"] += 1
                    continue
                self.waiting[m.key] = m
                heapq.heappush(self._waiting_order, m.key)
            else:
                self.counts["no accepted pass (unknown, rejected, or measured twice)"] += 1

    def _index(self) -> None:
        """The held tables not yet indexed, indexed (after the older ones)."""
        while self._unindexed:
            table = self._unindexed.popleft()
            for i, key in enumerate(zip(table.stamp_ns.tolist(), table.train_id.tolist(), strict=True)):
                self.held[key] = (table, i)
        self._unindexed_rows = 0

    def _pair(self, key: tuple[int, str], row: PassTable, m: Measurement) -> None:
        self.pending.append((key, row, bool(m.squeal_detected), float(m.squeal_level_db),
                             float(m.receiver_distance_m)))
        self.newest_taken_ns = max(self.newest_taken_ns, m.stamp_ns)

    def refit(self, stamp_ns: int) -> None:
        """The measured passes taken since the last fit joined to it, each state fitted anew and its
        P50 curve used from now on (a Calibration made, when any state has passes)."""
        if not self.pending:
            return
        pending = sorted(self.pending, key=lambda p: p[0])  # the same order whichever way they came
        self.pending = []
        checks = self.fit.observe(PassTable.concat([p[1] for p in pending]),
                                  *(np.array([p[i] for p in pending], float) for i in (2, 3, 4)))
        self.counts["paired"] += len(pending)
        states = []
        for code in FRICTION_NAMES:
            self.fit.keep_newest(code, self.window)
            if self.fit.seen[code][0]:
                self.fit.refine(code)
                k1_0, k2_0 = (float(x[0]) for x in self.configured.contact.creep(np.array([code])))
                states.append((code, (k1_0, k2_0), self.fit.quantiles(code), checks.get(code)))
        self._use((code, q) for code, _, q, _ in states)
        self.calibrations.append(Calibration(stamp_ns, tuple(states)))

    def _use(self, fitted: Iterable[tuple[int, CurveQuantiles]]) -> None:
        """The squeal model's site: the configured one with each fitted state's P50 curve."""
        curves = {}
        for code, q in fitted:
            name = FRICTION_NAMES[code]
            curves.update({f"creep_{name}_k1": q.k1[1], f"creep_{name}_k2": q.k2[1]})
        self.site = replace(self.configured, contact=replace(self.configured.contact, **curves))

    def take_calibrations(self) -> list[Calibration]:
        out, self.calibrations = self.calibrations, []
        return out

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The fit, the open window, the passes paired since the last fit with their squeal measures,
        and the held passes stamped after the newest measured one, for a checkpoint (none when
        disabled); measurements waiting for their passes are not kept (a replay after a restart
        sends them again)."""
        if not self.enabled:
            return {}
        # Taken table by table (a checkpoint is copied on the executor's thread: no per-pass Python).
        by_table: dict[int, tuple[PassTable, list[int]]] = {}
        for key, (table, i) in self.held.items():
            if key[0] > self.newest_taken_ns:
                by_table.setdefault(id(table), (table, []))[1].append(i)
        held = PassTable.concat([PassTable.empty(), *(t.take(np.array(rows)) for t, rows in by_table.values()),
                                 *(t.take(t.stamp_ns > self.newest_taken_ns) for t in self._unindexed)])
        paired = PassTable.concat([PassTable.empty(), *(p[1] for p in self.pending)])
        return {**self.fit.to_arrays(PREFIX),
                f"{PREFIX}scalars": np.array([self.window_end_ns, self.newest_taken_ns], np.int64),
                f"{PREFIX}paired_measures": np.array([p[2:] for p in self.pending], float).reshape(-1, 3),
                **{f"{PREFIX}held_{c}": getattr(held, c) for c in PassTable.columns()},
                **{f"{PREFIX}paired_{c}": getattr(paired, c) for c in PassTable.columns()}}

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        """Resume from to_arrays's records (ValueError, the site untouched, if they are not usable;
        a checkpoint without them resumes on the prior)."""
        if not self.enabled or f"{PREFIX}scalars" not in arrays:
            return
        fit = SquealFit(self.configured, self.fit.squeal_cfg, self.fit.cfg)
        fit.restore(arrays, PREFIX)
        held, paired = (PassTable(**{c: np.asarray(arrays[f"{PREFIX}{k}_{c}"]).astype(PassTable.DTYPES[c])
                                     for c in PassTable.columns()}) for k in ("held", "paired"))
        measures = np.asarray(arrays[f"{PREFIX}paired_measures"], float)
        scalars = np.asarray(arrays[f"{PREFIX}scalars"]).astype(np.int64, casting="same_kind")
        if scalars.shape != (2,) or scalars[0] < 0 or measures.shape != (len(paired), 3) \
                or not np.all(np.isin(measures[:, 0], (0.0, 1.0))):
            raise ValueError("squeal fit records: the open window's end is not a stamp, or the paired "
                             "passes' measures do not match them")
        self.fit = fit
        self.pending = [((int(paired.stamp_ns[i]), str(paired.train_id[i])), paired.take(slice(i, i + 1)),
                         bool(f), float(level), float(d)) for i, (f, level, d) in enumerate(measures)]
        self.window_end_ns, self.newest_taken_ns = int(scalars[0]), int(scalars[1])
        self.held, self.waiting, self._waiting_order = OrderedDict(), dict(self.waiting), list(self._waiting_order)
        self._unindexed, self._unindexed_rows = deque(), 0
        self.hold(held)
        self._use((code, fit.quantiles(code)) for code in FRICTION_NAMES if fit.seen[code][0])
