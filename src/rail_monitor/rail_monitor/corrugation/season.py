"""The last year's growth day by day: what the forecast interval uses as "the same season a year
earlier" once the history spans a year (rail_monitor.corrugation.forecast.interval).

Each day keeps the log growth of its passes per friction state per unit K_b (growth at the K_b in
use over that K_b: the growth law is first order in K_b, so a later re-fit scales it), and its
pass count. Passes are added in counting order with sequential sums, so one pass at a time or a
batch give the same bits.
"""

from __future__ import annotations

import numpy as np

from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.models.engine import corrugation_kernels

SEASON_DAYS = 365  # the profile a forecast follows: the year before the newest pass
KEPT_DAYS = SEASON_DAYS + 1


class DailyGrowth:
    """Growth per day (D, 4, B, P) per unit K_b and passes per day (D,), from ``first_day``
    (days since the epoch) on."""

    def __init__(self, shape: tuple[int, int]) -> None:
        self.shape = shape
        self.first_day = 0
        self.growth = np.zeros((0, 4, *shape))
        self.passes = np.zeros(0, np.int64)

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
            count = np.zeros(hi - lo + 1, np.int64)
            at = self.first_day - lo
            grown[at:at + len(self.passes)], count[at:at + len(self.passes)] = self.growth, self.passes
            self.growth, self.passes, self.first_day = grown, count, lo
        f = np.asarray(friction, np.int64) - 1
        scale = np.divide(1.0, k_b, out=np.zeros(4), where=k_b > 0)[f]
        corrugation_kernels(engine).add_by_day(self.growth, day - self.first_day, f, growth, scale)
        np.add.at(self.passes, day - self.first_day, 1)
        drop = len(self.passes) - KEPT_DAYS
        if drop > 0:
            self.growth, self.passes, self.first_day = self.growth[drop:], self.passes[drop:], self.first_day + drop

    def profile(self, newest_ns: int) -> np.ndarray | None:
        """The SEASON_DAYS days up to the newest pass's day, oldest first (SEASON_DAYS, 4, B, P) per
        unit K_b; None unless the history holds passes a full year before it."""
        end = int(newest_ns) // NS_PER_DAY - self.first_day + 1
        start = end - SEASON_DAYS
        if start < 0 or end > len(self.passes) or not self.passes[start:start + 7].any():
            return None
        return self.growth[start:end]
