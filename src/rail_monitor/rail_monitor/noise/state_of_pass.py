"""Which corrugation state a pass's rolling noise is predicted on: the one rule for the live
predictor and batch mode.

States arrive in time order (a state's stamp is the newest pass counted, its train id that pass's).
A pass is predicted on the state that includes it: the state with its own stamp and train id when
it was counted, else the latest state older than it, else (a pass older than every state but one
of equal stamp) the latest state of its stamp. It may be predicted once that state, or any later
one, has arrived.
"""

from __future__ import annotations

import bisect
from collections.abc import Sequence

import numpy as np


def _last_of_each(stamps: np.ndarray, trains: Sequence[str]) -> dict[tuple[int, str], int]:
    return {key: k for k, key in enumerate(zip(stamps.tolist(), trains, strict=True))}


def state_index(state_stamp_ns: np.ndarray, state_train_id: Sequence[str], pass_stamp_ns: np.ndarray,
                pass_train_id: Sequence[str]) -> np.ndarray:
    """Per pass, the index of the state it is predicted on, or -1 for none (stamps [ns], states in
    time order)."""
    s = np.asarray(state_stamp_ns, np.int64)
    t = np.asarray(pass_stamp_ns, np.int64)
    own = _last_of_each(s, list(state_train_id))
    mine = np.array([own.get(key, -1) for key in zip(t.tolist(), pass_train_id, strict=True)], np.int64)
    lo, hi = np.searchsorted(s, t, side="left"), np.searchsorted(s, t, side="right")
    older = np.where(lo > 0, lo - 1, np.where(hi > lo, hi - 1, -1))
    return np.where(mine >= 0, mine, older)


def state_arrived(state_stamp_ns: np.ndarray, state_train_id: Sequence[str], pass_stamp_ns: np.ndarray,
                  pass_train_id: Sequence[str]) -> np.ndarray:
    """Per pass, whether the state that includes it, or a later one, has arrived."""
    s = np.asarray(state_stamp_ns, np.int64)
    t = np.asarray(pass_stamp_ns, np.int64)
    own = _last_of_each(s, list(state_train_id))
    later = s.max(initial=np.iinfo(np.int64).min) > t
    return later | np.array([key in own for key in zip(t.tolist(), pass_train_id, strict=True)], bool)


def first_state_needed(state_stamp_ns: Sequence[int], earliest_pass_ns: int) -> int:
    """Index of the first state that a pass at or after earliest_pass_ns [ns] can be predicted on or
    wait for (states in time order): the latest state before that time, or 0. The states from there
    on give state_index and state_arrived the same answers as all of them."""
    return max(bisect.bisect_left(state_stamp_ns, earliest_pass_ns) - 1, 0)
