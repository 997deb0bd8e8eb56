"""Sliding windows of flags and the hysteresis search over a series (no ROS)."""

from __future__ import annotations

from collections import deque

import numpy as np


class Window:
    """Counts of two flags (raise level, clear level) over the last n inputs."""

    def __init__(self, n: int) -> None:
        self.flags: deque[tuple[bool, bool]] = deque(maxlen=n)
        self.over = self.near = 0

    def resized(self, n: int) -> Window:
        """A window of n inputs holding the newest of these flags."""
        out = Window(n)
        out.flags.extend(self.flags)
        out.over = sum(o for o, _ in out.flags)
        out.near = sum(r for _, r in out.flags)
        return out

    def push(self, over: np.ndarray, near: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Add flag pairs in order; returns the over and near counts and the window's length after
        each one (cumulative sums over the kept flags and the new ones)."""
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
