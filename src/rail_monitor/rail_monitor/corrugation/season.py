"""The last year's growth day by day: what the forecast interval uses as "the same season a year
earlier" once the history spans a year (rail_monitor.corrugation.forecast.interval).

Each day keeps the log growth of its passes per friction state per unit K_b (growth at the K_b in
use over that K_b: the growth law is first order in K_b, so a later re-fit scales it), and its
pass count per friction state. Passes are added in counting order with sequential sums, so one
pass at a time or a batch give the same bits.

The season repeats the year's traffic and weather (the wet and contaminated days), but not its
friction management: whether a dry rail was under a friction modifier is the operator's choice,
which an applicator started or stopped within the year has changed. The year's rail that was dry
or under the modifier is shared between them as in the recent passes (:func:`managed_as_recent`).
"""

from __future__ import annotations

import numpy as np

from rail_monitor.core.friction import FRICTION_DRY, FRICTION_MODIFIER
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.models.engine import corrugation_kernels

SEASON_DAYS = 365  # the profile a forecast follows: the year before the newest pass
KEPT_DAYS = SEASON_DAYS + 1


class DailyGrowth:
    """Growth per day (D, 4, B, P) per unit K_b and passes per day and friction state (D, 4), from
    ``first_day`` (days since the epoch) on."""

    def __init__(self, shape: tuple[int, int]) -> None:
        self.shape = shape
        self.first_day = 0
        self.growth = np.zeros((0, 4, *shape))
        self.passes = np.zeros((0, 4), np.int64)

    def add(self, stamp_ns: np.ndarray, friction: np.ndarray, growth: np.ndarray, k_b: np.ndarray,
            engine: str = "numpy") -> None:
        """Passes' stamps [ns], friction states (1-4), log growth (N, B, P) at K_b (4,); engine: of
        the sums (models.engine)."""
        if not len(stamp_ns):
            return
        day = np.asarray(stamp_ns, np.int64) // NS_PER_DAY
        if not len(self.passes):
            self.first_day = int(day.min())
        lo, hi = min(self.first_day, int(day.min())), max(self.first_day + len(self.passes) - 1, int(day.max()))
        if lo < self.first_day or hi >= self.first_day + len(self.passes):
            grown = np.zeros((hi - lo + 1, 4, *self.shape))
            count = np.zeros((hi - lo + 1, 4), np.int64)
            at = self.first_day - lo
            grown[at:at + len(self.passes)], count[at:at + len(self.passes)] = self.growth, self.passes
            self.growth, self.passes, self.first_day = grown, count, lo
        f = np.asarray(friction, np.int64) - 1
        scale = np.divide(1.0, k_b, out=np.zeros(4), where=k_b > 0)[f]
        corrugation_kernels(engine).add_by_day(self.growth, day - self.first_day, f, growth, scale)
        np.add.at(self.passes, (day - self.first_day, f), 1)
        drop = len(self.passes) - KEPT_DAYS
        if drop > 0:
            self.growth, self.passes, self.first_day = self.growth[drop:], self.passes[drop:], self.first_day + drop

    def profile(self, newest_ns: int, modifier_share: float | None = None) -> np.ndarray | None:
        """The SEASON_DAYS days up to the newest pass's day, oldest first (SEASON_DAYS, 4, B, P) per
        unit K_b; None unless the history holds passes a full year before it. modifier_share: of the
        recent passes on a dry or modified rail, the modifier's (:func:`modifier_share`); each day's
        such passes are shared so (:func:`managed_as_recent`), None leaves the year as it was."""
        end = int(newest_ns) // NS_PER_DAY - self.first_day + 1
        start = end - SEASON_DAYS
        if start < 0 or end > len(self.passes) or not self.passes[start:start + 7].any():
            return None
        if modifier_share is None:
            return self.growth[start:end]
        return managed_as_recent(self.growth[start:end], self.passes[start:end], modifier_share)


def modifier_share(friction: np.ndarray) -> float | None:
    """Of passes (friction states 1-4) on a dry or modified rail, the share under the friction
    modifier; None without any such pass."""
    friction = np.asarray(friction)
    dry, modified = np.count_nonzero(friction == FRICTION_DRY), np.count_nonzero(friction == FRICTION_MODIFIER)
    return modified / (dry + modified) if dry + modified else None


def managed_as_recent(growth: np.ndarray, passes: np.ndarray, share: float) -> np.ndarray:
    """A year's daily growth (S, 4, B, P) per unit K_b with each day's passes on a dry or modified
    rail shared as recently: a fraction ``share`` of them under the modifier, the rest dry.

    Each day keeps its passes per friction state (passes (S, 4)) and each state's growth per pass.
    A day without passes in one of the two states takes that state's growth per pass from the other
    state's, in the ratio of the two over the year. The wet and contaminated days are the weather's
    and are kept. Shared as the day itself was, a day is unchanged but for rounding. A year without
    passes in one of the two states, where a day would need their ratio, is returned unchanged.
    """
    d, m = FRICTION_DRY - 1, FRICTION_MODIFIER - 1
    n_d, n_m = passes[:, d].astype(float), passes[:, m].astype(float)
    need_m, need_d = (n_m == 0) & (n_d > 0) & (share > 0), (n_d == 0) & (n_m > 0) & (share < 1)
    if (need_m.any() or need_d.any()) and not (n_d.sum() and n_m.sum()):
        return growth
    per_d, per_m = _per_pass(growth[:, d], n_d), _per_pass(growth[:, m], n_m)
    year_d, year_m = _per_pass(growth[:, d].sum(axis=0), n_d.sum()), _per_pass(growth[:, m].sum(axis=0), n_m.sum())
    per_m[need_m] = per_d[need_m] * _per_pass(year_m, year_d)
    per_d[need_d] = per_m[need_d] * _per_pass(year_d, year_m)
    out = growth.copy()
    managed = (n_d + n_m)[:, None, None]
    out[:, d] = managed * (1.0 - share) * per_d
    out[:, m] = managed * share * per_m
    return out


def _per_pass(growth: np.ndarray, count: np.ndarray | float) -> np.ndarray:
    """growth over count, per day where count is per day ((S, B, P) over (S,)); 0 where it is 0."""
    count = np.asarray(count, float)
    count = count.reshape(count.shape + (1,) * (np.ndim(growth) - count.ndim))
    return np.divide(growth, count, out=np.zeros_like(growth), where=count != 0)
