"""The kept-pass store (rail_monitor.corrugation.history): RowQueue against plain array arithmetic."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.corrugation.history import RowQueue


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
