"""Which corrugation state a pass is predicted on (rail_monitor.noise.state_of_pass), against a plain
scan of the states newest first, on streams with equal stamps, duplicates and late passes."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.noise.state_of_pass import first_state_needed, state_arrived, state_index


def _scan(states, stamp, train):
    """The rule read literally: newest first, the first state not newer than the pass that is not of
    its own stamp with another train; failing that, the newest state of its stamp."""
    for k in range(len(states) - 1, -1, -1):
        s, t = states[k]
        if s < stamp or (s == stamp and t == train):
            return k
    same = [k for k, (s, _) in enumerate(states) if s == stamp]
    return same[-1] if same else -1


def _scan_arrived(states, stamp, train):
    return any(s > stamp or (s == stamp and t == train) for s, t in states)


@pytest.mark.parametrize("seed", range(5))
def test_the_vectorised_rule_equals_the_scan(seed):
    rng = np.random.default_rng(seed)
    stamps = np.sort(rng.integers(0, 40, 60))            # many equal stamps
    trains = [f"T{int(x)}" for x in rng.integers(0, 4, 60)]
    states = list(zip(stamps.tolist(), trains, strict=True))
    pass_stamp = rng.integers(-5, 45, 200)
    pass_train = [f"T{int(x)}" for x in rng.integers(0, 5, 200)]
    got = state_index(stamps, trains, pass_stamp, pass_train)
    want = [_scan(states, int(s), t) for s, t in zip(pass_stamp, pass_train, strict=True)]
    assert got.tolist() == want
    arrived = state_arrived(stamps, trains, pass_stamp, pass_train)
    assert arrived.tolist() == [_scan_arrived(states, int(s), t) for s, t in zip(pass_stamp, pass_train, strict=True)]


@pytest.mark.parametrize("seed", range(5))
def test_the_states_from_the_first_needed_give_the_same_answers_as_all(seed):
    # The live predictor looks only at the states from first_state_needed of its earliest pending pass.
    rng = np.random.default_rng(seed)
    stamps = np.sort(rng.integers(0, 40, 60))
    trains = [f"T{int(x)}" for x in rng.integers(0, 4, 60)]
    for earliest in (-3, 0, 7, 20, 39, 50):
        first = first_state_needed(stamps.tolist(), earliest)
        pass_stamp = rng.integers(earliest, 55, 50)
        pass_train = [f"T{int(x)}" for x in rng.integers(0, 5, 50)]
        full = state_index(stamps, trains, pass_stamp, pass_train)
        tail = state_index(stamps[first:], trains[first:], pass_stamp, pass_train)
        assert np.array_equal(np.where(tail >= 0, tail + first, -1), full)
        assert np.array_equal(state_arrived(stamps[first:], trains[first:], pass_stamp, pass_train),
                              state_arrived(stamps, trains, pass_stamp, pass_train))


def test_cases_by_name():
    stamps, trains = np.array([10, 20, 20, 30]), ["A", "B", "C", "D"]
    idx = state_index(stamps, trains, np.array([20, 20, 25, 5, 10, 40]), ["C", "X", "Q", "Z", "A", "E"])
    # own state; same stamp, another train: the latest older; between; before all; own; after all
    assert idx.tolist() == [2, 0, 2, -1, 0, 3]
    assert state_arrived(stamps, trains, np.array([30, 35, 20]), ["D", "E", "X"]).tolist() == [True, False, True]
    assert state_index(np.array([], np.int64), [], np.array([1]), ["A"]).tolist() == [-1]
    assert state_arrived(np.array([], np.int64), [], np.array([1]), ["A"]).tolist() == [False]
