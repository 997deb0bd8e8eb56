"""The kept-pass store (rail_monitor.corrugation.history): RowQueue and KeptPasses against plain array arithmetic."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.corrugation.history import COLUMNS, DTYPES, KeptPasses, RowQueue, dropped


@pytest.mark.parametrize("seed", range(4))
def test_row_queue_holds_what_concatenation_and_masking_hold(seed):
    # The estimator's growth prefix sums: appended pass by pass or in chunks, pruned from the front
    # (or, after a late pass, anywhere). The queue must hold exactly the rows a copy-every-time
    # array holds, and a view taken before later appends and drops must keep its values.
    rng = np.random.default_rng(seed)
    plain = np.zeros((0, 3, 2))
    queue = RowQueue(plain)
    views = []
    for _ in range(300):
        rows = rng.normal(size=(int(rng.choice([1, 1, 1, 5, 40])), 3, 2))
        plain = np.concatenate([plain, rows])
        queue.append(rows)
        gone = np.zeros(len(plain), bool)
        gone[:int(rng.integers(0, 4))] = True            # the oldest passes leave the history
        if rng.random() < 0.05:
            gone[rng.integers(0, len(plain))] = True     # a pass counted late leaves out of order
        plain = plain[~gone]
        queue.keep(~gone)
        assert len(queue) == len(plain)
        assert np.array_equal(queue.rows, plain) and np.array_equal(queue, plain)
        views.append((queue.rows, plain.copy()))
    for view, want in views:
        assert np.array_equal(view, want)


def test_row_queue_keeps_nothing_or_everything():
    queue = RowQueue(np.arange(12.0).reshape(6, 2))
    queue.keep(np.ones(6, bool))
    assert np.array_equal(queue.rows, np.arange(12.0).reshape(6, 2))
    queue.keep(np.zeros(6, bool))
    assert len(queue) == 0 and queue.rows.shape == (0, 2)
    queue.append(np.ones((2, 2)))
    assert np.array_equal(queue.rows, np.ones((2, 2)))


@pytest.mark.parametrize("seed", range(3))
def test_kept_passes_hold_what_concatenation_and_masking_hold(seed):
    # The estimator counts passes and prunes those older than its history: in time order the oldest
    # leave as a leading slice found by bisection; after a late pass, by a mask. Either way the
    # columns, the newest stamp and the passes seen must be those of copy-every-time arrays.
    rng = np.random.default_rng(seed)
    kept, plain, stamp = KeptPasses(), {name: np.zeros(0, DTYPES[name]) for name in COLUMNS}, 0
    for step in range(400):
        n = int(rng.choice([1, 1, 1, 3, 20]))
        stamp += int(rng.integers(1, 100))
        stamps = stamp + np.cumsum(rng.integers(0, 5, n))
        if rng.random() < 0.03:
            stamps = stamps - 500                         # a late pass, counted after newer ones
        cols = {"stamp_ns": stamps, "train_id": np.array([f"t{step}-{i}" for i in range(n)], object),
                **{name: rng.integers(0, 4, n).astype(DTYPES[name]) for name in COLUMNS[2:]}}
        kept.extend(**cols)
        plain = {name: np.concatenate([plain[name], cols[name]]) for name in COLUMNS}
        horizon = int(stamps.max()) - int(rng.integers(100, 400))
        gone = kept.older_than(horizon)
        assert isinstance(gone, slice) == bool(np.all(np.diff(plain["stamp_ns"]) >= 0))
        want = plain["stamp_ns"] < horizon
        assert dropped(gone) == want.sum() and np.array_equal(kept.axles[gone], plain["axles"][want])
        kept.drop(gone)
        plain = {name: column[~want] for name, column in plain.items()}
        for name in COLUMNS:
            assert np.array_equal(getattr(kept, name), plain[name]) and getattr(kept, name).dtype == DTYPES[name]
        assert len(kept) == len(plain["stamp_ns"])
        assert kept.newest_ns() == (int(plain["stamp_ns"].max()) if len(kept) else None)
        assert kept.seen() == set(zip(plain["stamp_ns"].tolist(), plain["train_id"].tolist(), strict=True))
