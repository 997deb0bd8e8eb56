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


def _own_state(state_train_id: Sequence[str], pass_train_id: Sequence[str], lo: np.ndarray,
               hi: np.ndarray) -> np.ndarray:
    """Per pass, the last state of its own stamp and train id, or -1 (states [lo, hi) are those of
    its stamp). Most passes have at most one state of their stamp, compared at once; the few with
    more are looked up one by one."""
    own = np.full(len(lo), -1, np.int64)
    width = hi - lo
    one = np.flatnonzero(width == 1)
    if len(one):
        trains = np.asarray(pass_train_id, dtype=object)
        states = np.asarray(state_train_id, dtype=object)
        own[one] = np.where(states[lo[one]] == trains[one], lo[one], -1)
    for i in np.flatnonzero(width > 1).tolist():
        same = [k for k in range(int(lo[i]), int(hi[i])) if state_train_id[k] == pass_train_id[i]]
        own[i] = same[-1] if same else -1
    return own


def state_index(state_stamp_ns: np.ndarray, state_train_id: Sequence[str], pass_stamp_ns: np.ndarray,
                pass_train_id: Sequence[str]) -> np.ndarray:
    """Per pass, the index of the state it is predicted on, or -1 for none (stamps [ns], states in
    time order)."""
    s = np.asarray(state_stamp_ns, np.int64)
    t = np.asarray(pass_stamp_ns, np.int64)
    lo, hi = np.searchsorted(s, t, side="left"), np.searchsorted(s, t, side="right")
    mine = _own_state(state_train_id, pass_train_id, lo, hi)
    older = np.where(lo > 0, lo - 1, np.where(hi > lo, hi - 1, -1))
    return np.where(mine >= 0, mine, older)


def state_arrived(state_stamp_ns: np.ndarray, state_train_id: Sequence[str], pass_stamp_ns: np.ndarray,
                  pass_train_id: Sequence[str]) -> np.ndarray:
    """Per pass, whether the state that includes it, or a later one, has arrived."""
    s = np.asarray(state_stamp_ns, np.int64)
    t = np.asarray(pass_stamp_ns, np.int64)
    lo, hi = np.searchsorted(s, t, side="left"), np.searchsorted(s, t, side="right")
    later = s.max(initial=np.iinfo(np.int64).min) > t
    return later | (_own_state(state_train_id, pass_train_id, lo, hi) >= 0)


def first_state_needed(state_stamp_ns: Sequence[int], earliest_pass_ns: int) -> int:
    """Index of the first state that a pass at or after earliest_pass_ns [ns] can be predicted on or
    wait for (states in time order): the latest state before that time, or 0. The states from there
    on give state_index and state_arrived the same answers as all of them."""
    return max(bisect.bisect_left(state_stamp_ns, earliest_pass_ns) - 1, 0)
