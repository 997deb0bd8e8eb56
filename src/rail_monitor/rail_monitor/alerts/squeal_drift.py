"""Squeal model drift: a friction state whose measured squeal share leaves the share the model
predicted, fit window after fit window (no ROS).

At each fit of the squeal model (engine.squeal_site, rail_msgs/SquealCalibration) a state that
had at least ``min_passes`` measured passes in the window is judged: its share flagged squealing
against the P10-P90 the model predicted for those passes before the fit took them
(squeal.share_check). Below P10, or above P90, ``windows`` judged windows running on the same side
raise the state's drift alert; a judged window inside P10-P90 clears it and ends the run; a window
with fewer passes leaves both as they are. A right model puts a window on one given side one time
in ten, so three running on one side come by chance once in 500 fits of a state.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True)
class DriftVerdict:
    """A judged window of a state: its side (-1 below P10, 0 inside, +1 above P90), how many judged
    windows running have been on it, its passes, those flagged squealing, and the predicted P10
    and P90 of the share [-]."""

    state: str
    side: int
    running: int
    passes: int
    squealed: int
    p10: float
    p90: float

    @property
    def share(self) -> float:
        return self.squealed / self.passes

    @property
    def summary(self) -> str:
        """The alert's line: raised (outside) or cleared (inside)."""
        share = (f"{self.squealed} of {self.passes}, {100 * self.share:.1f} %, predicted P10-P90 "
                 f"{100 * self.p10:.1f}-{100 * self.p90:.1f} %")
        if not self.side:
            return f"squeal model drift: {self.state} cleared ({share})"
        return (f"squeal model drift: {self.state} passes heard squealing {'more' if self.side > 0 else 'less'} "
                f"than predicted, {self.running} fits running ({share})")


class SquealDrift:
    """The runs of judged windows outside the predicted share, per friction state."""

    def __init__(self, windows: int, min_passes: int) -> None:
        self.windows, self.min_passes = windows, min_passes
        self.runs: dict[str, tuple[int, int]] = {}  # state -> (side, windows running on it)

    def judge(self, state: str, passes: int, squealed: int, p10: float, p90: float) -> DriftVerdict | None:
        """One window of a state (None: too few passes to judge, or no prediction)."""
        if passes < self.min_passes or not p10 <= p90:  # NaN: no prediction
            return None
        share = squealed / passes
        side = -1 if share < p10 else 1 if share > p90 else 0
        was, running = self.runs.get(state, (0, 0))
        running = running + 1 if side == was else 1
        self.runs[state] = (side, running)
        return DriftVerdict(state, side, running, passes, squealed, p10, p90)

    def changes(self, windows: Iterable[tuple[str, int, int, float, float]]) -> list[DriftVerdict]:
        """The judged windows of one fit that may raise (``windows`` running outside) or clear
        (inside): (state, passes, flagged squealing, P10, P90) each."""
        out = [self.judge(*w) for w in windows]
        return [v for v in out if v is not None and (not v.side or v.running >= self.windows)]
