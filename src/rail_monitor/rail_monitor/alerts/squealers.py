"""Repeat squealers: the vehicles (or, where a station names no vehicles, the trains) that a
station hears squealing far more often than the site's other passes in the same conditions.

The conditions are what the squeal model makes of a pass (its predicted risk class, which folds in
the angle of attack, the friction state, the speed and the class's wheel), and the reference is
the vehicle's own fleet without it: a station flags trains, so every vehicle of a squealing train
is counted squealing, and a bad wagon in a freight train of half its fleet raises the share of
every wagon it runs with. The vehicles that run together are found as they do (a union-find over
consists); per fleet and risk class the measured trains and the squealing ones are counted, and for
each vehicle its own. The share of its fleet's trains without it, alike in risk, p = (k + 1) /
(n + 2) (Laplace-smoothed), is what it would show as any other; over its last ``window`` measured
passes (a wheel reprofiled leaves the window) its passes n, squealing passes k and expected count
E = sum of p give the chance of k or more, the binomial tail P(X >= k), X ~ B(n, E / n). A vehicle
of at least ``min_passes`` passes there is flagged when that chance falls below ``raise_p`` and
cleared when it rises above ``clear_p``. Trains without named vehicles are one fleet, keyed by
train id.
"""

from __future__ import annotations

from collections import Counter, deque
from dataclasses import dataclass, field

from scipy.special import bdtrc  # the binomial tail (scipy.stats would cost a node's start-up 0.4 s)

KEPT = 10_000  # vehicles counted: past this, the half with most passes is kept


@dataclass
class Tally:
    """A key's last measured passes: how many, how many squealed, how many were expected to."""

    passes: int = 0
    squealed: int = 0
    expected: float = 0.0
    recent: deque = field(default_factory=deque)  # (squealed, expected) per pass, oldest first

    def add(self, squealed: bool, expected: float, window: int) -> None:
        self.recent.append((int(squealed), expected))
        self.passes, self.squealed, self.expected = self.passes + 1, self.squealed + int(squealed), \
            self.expected + expected
        if len(self.recent) > window:  # a wheel reprofiled leaves the window, and the flag clears
            k, e = self.recent.popleft()
            self.passes, self.squealed, self.expected = self.passes - 1, self.squealed - k, self.expected - e

    def tail(self) -> float:
        """P(X >= squealed) for X ~ B(passes, expected / passes)."""
        if not self.passes:
            return 1.0
        return float(bdtrc(self.squealed - 1, self.passes, min(max(self.expected / self.passes, 1e-9), 1.0)))


@dataclass(frozen=True)
class Verdict:
    key: str
    stamp_ns: int
    flagged: bool       # raised (True) or cleared (False)
    passes: int         # its measured passes in the window
    squealed: int       # of which squealing
    expected: float     # expected squealing at the site's shares [-]
    chance: float       # P(X >= squealed) under the site's shares [-]


class RepeatSquealers:
    """Per key (``vehicle <id>`` or ``train <id>``) its recent tally, and the counts it is weighed
    against: per fleet (vehicles that run together, found as they do) and risk class, the measured
    passes and squealing ones, and each key's own share of them."""

    def __init__(self, window: int, min_passes: int, raise_p: float, clear_p: float) -> None:
        self.window, self.min_passes, self.raise_p, self.clear_p = window, min_passes, raise_p, clear_p
        self.tallies: dict[str, Tally] = {}
        self.own: dict[str, Counter] = {}       # key -> Counter {(risk, 0): passes, (risk, 1): squealing}
        self.fleet: dict[str, str] = {}         # key -> another key of its fleet (union-find parent)
        self.by_fleet: dict[str, Counter] = {}  # fleet root -> Counter as own's, over the fleet's trains
        self.flagged: set[str] = set()

    def _root(self, key: str) -> str:
        while self.fleet.get(key, key) != key:
            self.fleet[key] = self.fleet.get(self.fleet[key], self.fleet[key])  # path halving
            key = self.fleet[key]
        return key

    def _fleet_of(self, keys: list[str]) -> str:
        """The fleet root of a train's keys, their fleets merged (vehicles of one train run together)."""
        roots = {self._root(k) for k in keys}
        root = min(roots)
        for other in roots - {root}:
            self.fleet[other] = root
            self.by_fleet.setdefault(root, Counter()).update(self.by_fleet.pop(other, Counter()))
        for k in keys:
            self.fleet.setdefault(k, root)
        return root

    def add(self, stamp_ns: int, train_id: str, vehicles: tuple[str, ...], squealed: bool, risk: int) -> list[Verdict]:
        """One measured pass; the keys it raises or clears."""
        keys = [f"vehicle {v}" for v in vehicles] or [f"train {train_id}"]
        fleet = self.by_fleet.setdefault(self._fleet_of(keys if vehicles else ["trains"]), Counter())
        r, hit = int(risk), int(squealed)
        out = []
        for key in keys:
            own = self.own.setdefault(key, Counter())
            # The fleet's trains without this key, alike in risk: what it would show as any other.
            n, k = fleet[(r, 0)] - own[(r, 0)], fleet[(r, 1)] - own[(r, 1)]
            t = self.tallies.setdefault(key, Tally())
            t.add(squealed, (k + 1) / (n + 2), self.window)
            own[(r, 0)] += 1
            own[(r, 1)] += hit
            out += self._verdict(key, t, stamp_ns)
        fleet[(r, 0)] += 1
        fleet[(r, 1)] += hit
        if len(self.tallies) > KEPT:  # a new train id per pass must not grow it for ever
            keep = {key for key, _ in Counter({key: t.passes for key, t in self.tallies.items()}).most_common(
                KEPT // 2)} | (self.flagged & set(self.tallies))
            self.tallies = {key: self.tallies[key] for key in keep}
            self.own = {key: self.own[key] for key in keep if key in self.own}
        return out

    def _verdict(self, key: str, t: Tally, stamp_ns: int) -> list[Verdict]:
        # The tail only where it can be small: a chance below a half needs more than the expected count.
        if key not in self.flagged and t.passes >= self.min_passes and t.squealed > t.expected:
            chance = t.tail()
            if chance < self.raise_p:
                self.flagged.add(key)
                return [Verdict(key, stamp_ns, True, t.passes, t.squealed, t.expected, chance)]
        elif key in self.flagged:
            chance = t.tail()
            if chance > self.clear_p:
                self.flagged.discard(key)
                return [Verdict(key, stamp_ns, False, t.passes, t.squealed, t.expected, chance)]
        return []
