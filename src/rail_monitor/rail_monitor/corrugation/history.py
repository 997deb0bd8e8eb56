"""The passes a corrugation state keeps: their identity (so none is counted twice) and what the
forecast and the advice need (class, friction state, contact regime, speed, axles, and the wheel
load and lateral creepage from which the regime follows in another friction state)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

COLUMNS = ("stamp_ns", "train_id", "class_idx", "friction", "regime", "speed", "axles", "load", "creepage")


@dataclass
class KeptPasses:
    """Columns of the kept passes, in the order they were counted; their (stamp [ns], train_id)
    keys are the passes seen."""

    stamp_ns: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    train_id: np.ndarray = field(default_factory=lambda: np.zeros(0, object))
    class_idx: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    friction: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    regime: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))    # core.contact.REGIME_*
    speed: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float64))   # [m/s]
    axles: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    load: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float64))    # wheel load [N]
    creepage: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float64))  # lateral [-]
    _seen: set[tuple[int, str]] | None = field(default=None, repr=False, compare=False)

    def __len__(self) -> int:
        return len(self.stamp_ns)

    def seen(self) -> set[tuple[int, str]]:
        """The keys of the kept passes as a set, built when first asked for after a change (passes
        newer than every kept one need no look-up: most calls never build it)."""
        if self._seen is None:
            self._seen = set(zip(self.stamp_ns.tolist(), self.train_id.tolist(), strict=True))
        return self._seen

    def newest_ns(self) -> int | None:
        """The newest kept stamp [ns] (None: none kept)."""
        return int(self.stamp_ns.max()) if len(self.stamp_ns) else None

    def extend(self, **cols: np.ndarray) -> None:
        """Append passes."""
        for name in COLUMNS:
            setattr(self, name, np.concatenate([getattr(self, name), cols[name]]))
        self._seen = None

    def drop(self, gone: np.ndarray) -> None:
        """Forget the passes of a boolean mask."""
        for name in COLUMNS:
            setattr(self, name, getattr(self, name)[~gone])
        self._seen = None


class RowQueue:
    """Rows of an array appended at the back and dropped from the front, each in amortised O(1)
    per row: the live rows are a view of a buffer with room behind them, moved to a new buffer
    only when that room is used up. Rows once written are never written again, so a view taken
    earlier (``rows``) keeps its values whatever is appended or dropped later."""

    def __init__(self, rows: np.ndarray) -> None:
        self._buf, self._lo, self._hi = np.array(rows, float), 0, len(rows)

    @property
    def rows(self) -> np.ndarray:
        return self._buf[self._lo:self._hi]

    def __len__(self) -> int:
        return self._hi - self._lo

    def __array__(self, dtype: object = None, copy: bool | None = None) -> np.ndarray:
        return np.array(self.rows, dtype) if copy else np.asarray(self.rows, dtype)

    def append(self, rows: np.ndarray) -> None:
        n, live = len(rows), len(self)
        if self._hi + n > len(self._buf):
            buf = np.empty((2 * live + n, *self._buf.shape[1:]))
            buf[:live] = self.rows
            self._buf, self._lo, self._hi = buf, 0, live
        self._buf[self._hi:self._hi + n] = rows
        self._hi += n

    def keep(self, mask: np.ndarray) -> None:
        """Keep the rows of a boolean mask (dropping a leading run costs nothing)."""
        k = int(np.argmax(mask)) if mask.any() else len(mask)
        if mask[k:].all():
            self._lo += k
        else:
            self._buf, self._lo, self._hi = self.rows[mask], 0, int(mask.sum())
