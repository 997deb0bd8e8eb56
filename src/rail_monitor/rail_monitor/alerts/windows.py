"""Sliding windows of flags and the hysteresis search over a series (no ROS)."""

from __future__ import annotations

from collections import deque
from itertools import islice

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
        each one. The counts run on from the window's totals, less the flags that leave it (the
        oldest kept, then new ones), so a push costs what it adds, not the window's length."""
        n, m, k = self.flags.maxlen or 0, len(over), len(self.flags)
        o, r = np.asarray(over, bool).astype(np.int64), np.asarray(near, bool).astype(np.int64)
        first = max(0, n - k)      # the new flags taken before the window is full: none leaves
        gone = max(0, m - first)   # one flag leaves for each of the others
        head = np.array(list(islice(self.flags, min(gone, k))), np.int64).reshape(-1, 2)
        leave_o, leave_r = np.zeros(m, np.int64), np.zeros(m, np.int64)
        leave_o[first:] = np.concatenate([head[:, 0], o])[:gone]
        leave_r[first:] = np.concatenate([head[:, 1], r])[:gone]
        over_counts = self.over + np.cumsum(o) - np.cumsum(leave_o)
        near_counts = self.near + np.cumsum(r) - np.cumsum(leave_r)
        if m:
            self.flags.extend(zip(o.astype(bool).tolist(), r.astype(bool).tolist(), strict=True))
            self.over, self.near = int(over_counts[-1]), int(near_counts[-1])
        return over_counts, near_counts, np.minimum(k + np.arange(1, m + 1), n)


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
