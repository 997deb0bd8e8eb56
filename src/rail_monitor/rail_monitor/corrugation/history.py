"""The passes a corrugation state keeps: their identity (so none is counted twice) and what the
forecast and the advice need (class, friction state, contact regime, speed, axles, and the wheel
load and lateral creepage from which the regime follows in another friction state)."""

from __future__ import annotations

import numpy as np

COLUMNS = ("stamp_ns", "train_id", "class_idx", "friction", "regime", "speed", "axles", "load", "creepage")


DTYPES = {"stamp_ns": np.int64, "train_id": object, "class_idx": np.int64, "friction": np.int64,
          "regime": np.int64, "speed": np.float64, "axles": np.int64, "load": np.float64, "creepage": np.float64}


class KeptPasses:
    """Columns of the kept passes, in the order they were counted; their (stamp [ns], train_id)
    keys are the passes seen. Columns: stamp_ns, train_id, class_idx, friction, regime
    (core.contact.REGIME_*), speed [m/s], axles, load (wheel load [N]) and creepage (lateral [-]).

    Each column is a :class:`RowQueue`, so a pass counted and the oldest passes leaving the history
    cost the same however many are kept (a live pass at a busy site with a long history)."""

    def __init__(self, **cols: np.ndarray) -> None:
        self._columns = {name: RowQueue(np.asarray(cols.get(name, []), DTYPES[name])) for name in COLUMNS}
        self._seen: set[tuple[int, str]] | None = None
        stamps = self._columns["stamp_ns"].rows
        self._newest = int(stamps.max()) if len(stamps) else None
        self._in_time_order = bool(np.all(np.diff(stamps) >= 0))

    stamp_ns = property(lambda self: self._columns["stamp_ns"].rows)
    train_id = property(lambda self: self._columns["train_id"].rows)
    class_idx = property(lambda self: self._columns["class_idx"].rows)
    friction = property(lambda self: self._columns["friction"].rows)
    regime = property(lambda self: self._columns["regime"].rows)
    speed = property(lambda self: self._columns["speed"].rows)
    axles = property(lambda self: self._columns["axles"].rows)
    load = property(lambda self: self._columns["load"].rows)
    creepage = property(lambda self: self._columns["creepage"].rows)

    def __len__(self) -> int:
        return len(self._columns["stamp_ns"])

    def seen(self) -> set[tuple[int, str]]:
        """The keys of the kept passes as a set, built when first asked for after a change (passes
        newer than every kept one need no look-up: most calls never build it)."""
        if self._seen is None:
            self._seen = set(zip(self.stamp_ns.tolist(), self.train_id.tolist(), strict=True))
        return self._seen

    @property
    def in_time_order(self) -> bool:
        """Whether the kept passes' stamps never decrease in counting order (a late pass breaks it)."""
        return self._in_time_order

    def newest_ns(self) -> int | None:
        """The newest kept stamp [ns] (None: none kept)."""
        return self._newest

    def extend(self, **cols: np.ndarray) -> None:
        """Append passes."""
        stamps = np.asarray(cols["stamp_ns"], np.int64)
        if len(stamps):
            self._in_time_order &= bool((self._newest is None or stamps[0] >= self._newest)
                                        and np.all(np.diff(stamps) >= 0))
            top = int(stamps.max())
            self._newest = top if self._newest is None else max(top, self._newest)
        for name in COLUMNS:
            self._columns[name].append(np.asarray(cols[name], DTYPES[name]))
        self._seen = None

    def older_than(self, stamp_ns: int) -> slice | np.ndarray:
        """The kept passes stamped before stamp_ns: a leading slice when the kept passes are in time
        order (found by bisection), else a boolean mask."""
        if self._in_time_order:
            return slice(0, int(np.searchsorted(self.stamp_ns, stamp_ns, side="left")))
        return self.stamp_ns < stamp_ns

    def drop(self, gone: slice | np.ndarray) -> None:
        """Forget the passes of a leading slice or a boolean mask."""
        for name in COLUMNS:
            self._columns[name].drop(gone)
        stamps = self.stamp_ns
        if not len(stamps):
            self._newest, self._in_time_order = None, True
        elif not isinstance(gone, slice):
            self._newest, self._in_time_order = int(stamps.max()), bool(np.all(np.diff(stamps) >= 0))
        self._seen = None


def dropped(gone: slice | np.ndarray) -> int:
    """How many rows a leading slice or a boolean mask (KeptPasses.older_than) selects."""
    return gone.stop if isinstance(gone, slice) else int(np.count_nonzero(gone))


class RowQueue:
    """Rows of an array appended at the back and dropped from the front, each in amortised O(1)
    per row: the live rows are a view of a buffer with room behind them, moved to a new buffer
    only when that room is used up. Rows once written are never written again, so a view taken
    earlier (``rows``) keeps its values whatever is appended or dropped later."""

    def __init__(self, rows: np.ndarray) -> None:
        self._buf, self._lo, self._hi = np.array(rows), 0, len(rows)

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
            buf = np.empty((2 * live + n, *self._buf.shape[1:]), self._buf.dtype)
            buf[:live] = self.rows
            self._buf, self._lo, self._hi = buf, 0, live
        self._buf[self._hi:self._hi + n] = rows
        self._hi += n

    def drop(self, gone: slice | np.ndarray) -> None:
        """Drop a leading slice of rows (nothing moves) or the rows of a boolean mask."""
        if isinstance(gone, slice):
            self._lo += gone.stop
        else:
            self.keep(~gone)

    def keep(self, mask: np.ndarray) -> None:
        """Keep the rows of a boolean mask (dropping a leading run costs nothing)."""
        k = int(np.argmax(mask)) if mask.any() else len(mask)
        if mask[k:].all():
            self._lo += k
        else:
            self._buf, self._lo, self._hi = self.rows[mask], 0, int(mask.sum())
