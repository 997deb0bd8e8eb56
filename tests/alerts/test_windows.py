"""Sliding windows of flags (rail_monitor.alerts.windows) against a plain count over the last n."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.alerts.windows import Window


@pytest.mark.parametrize("n", [0, 1, 3, 50])
@pytest.mark.parametrize("seed", range(3))
def test_window_counts_equal_a_plain_count_whatever_the_chunks(n, seed):
    # The live node pushes one flag at a time, batch mode whole histories: in any chunking each
    # push must give, after each flag, the flags set among the last n and how many there are.
    rng = np.random.default_rng(seed)
    over, near = rng.random(400) < 0.3, rng.random(400) < 0.6
    w, got = Window(n), []
    cuts = np.sort(rng.choice(np.arange(1, 400), size=40, replace=False))
    for part in np.split(np.arange(400), cuts):
        got.append(np.stack(w.push(over[part], near[part])))
    got = np.concatenate(got, axis=1)
    want = np.array([[over[max(0, i + 1 - n):i + 1].sum() if n else 0 for i in range(400)],
                     [near[max(0, i + 1 - n):i + 1].sum() if n else 0 for i in range(400)],
                     [min(i + 1, n) for i in range(400)]])
    assert np.array_equal(got, want)
    assert (w.over, w.near) == (int(want[0, -1]), int(want[1, -1]))
    assert w.push(np.zeros(0, bool), np.zeros(0, bool))[0].shape == (0,)


def test_a_resized_window_holds_the_newest_flags():
    w = Window(4)
    w.push(np.array([1, 1, 0, 1, 0, 1], bool), np.array([1, 0, 0, 1, 1, 1], bool))
    small = w.resized(2)
    assert list(small.flags) == [(False, True), (True, True)]
    assert (small.over, small.near) == (1, 2)
    assert small.push(np.array([True]), np.array([False]))[0].tolist() == [2]
