"""Why the speed advice cuts as much as it does and no more, and what it costs the timetable.

The advice is the linear programme of :mod:`rail_monitor.advice.speed_plan`; each of its limits
is relaxed in turn and the programme solved again. A limit binds when dropping it lowers the peak
growth: the advice says which bind, and the grinding interval factor the plan would reach
without each (and without all of them). The band width is relaxed by halving it (a finer plan
the operator would have to publish). Not relaxed: each class's mean speed, kept as the source
paper keeps it, and each class's speed range.

The timetable cost is the change of running time over the length the advised speeds hold,
``corrugation.advice_length_m`` (L): per class the mean of L/v over the advised band centres
less that over the current ones, pass-weighted over the classes; and the worst, the largest
L/v_low - L/v_mean of a band the plan uses (v_low its lower edge, v_mean the class's mean
speed). With the mean speed kept, spreading speeds can only lengthen the mean running time
(Jensen's inequality on 1/v), so the cost is never negative. The UQ paper's advised speeds
changed timetables by less than 20 s (Rail Mechanics Group, The University of Queensland, "A
smorgasbord of railway dynamic and acoustic phenomena", section 2.1).
"""

from __future__ import annotations

from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np

from rail_monitor.advice.consequences import Consequences
from rail_monitor.advice.plan import AdviceProblem, advice_problem
from rail_monitor.advice.speed_plan import SpeedPlan, plan_growth
from rail_monitor.corrugation.estimator import CorrugationEstimator

MIN_SPEED_MPS = 0.5  # a band from standstill: its running time taken at this speed
BINDS = 1e-6  # a relaxation lowering the peak growth by more than this fraction: the limit binds


@dataclass(frozen=True)
class Relaxed:
    """One limit of the advice, dropped: whether it binds and the interval factor without it [-]."""

    limit: str
    binds: bool
    interval_factor: float


@dataclass(frozen=True)
class AdviceExplained:
    """The advice's interval factor [-], each limit relaxed, and its timetable cost [s per train]."""

    interval_factor: float
    relaxed: list[Relaxed]
    length_m: float
    extra_running_time_s: float        # mean over trains, advised less current
    worst_extra_running_time_s: float  # the slowest advised band's train against its class's mean

    def lines(self) -> list[str]:
        binding = [r.limit for r in self.relaxed if r.binds and r.limit != ALL]
        out = [f"limited by: {', '.join(binding) if binding else 'none of its limits (the speeds and traffic)'}"]
        out += [f"  without {r.limit}: grinding interval x{r.interval_factor:.2f}"
                + ("" if r.binds else " (not binding)") for r in self.relaxed]
        out.append("  never relaxed: each class's mean speed (its running time) and its speed range")
        out.append(f"timetable: {self.extra_running_time_s:+.1f} s per train on average, at most "
                   f"{self.worst_extra_running_time_s:+.1f} s, over {self.length_m:g} m (the paper: under 20 s)")
        return out


ALL = "the noise, squeal and per-band limits together"


def explain(est: CorrugationEstimator, consequences: Consequences, pool: Executor | None = None) -> AdviceExplained:
    """The advice on the kept passes with each limit relaxed, and its timetable cost (ValueError as
    for advise)."""
    p = advice_problem(est, consequences, pool)
    base = p.solve()
    now = float(plan_growth(p.growth, p.axle_weight, p.current).max())

    def factor(plan: SpeedPlan) -> float:
        peak = min(plan.peak_growth, now)
        return now / peak if peak > 0 else float("inf")

    models = list(consequences.noise.models)
    noise_only = p.limits[:len(models)]  # the squeal limit is last
    variants = [(f"the noise limit ({m}, +{est.cfg.advice_noise_rise_dba:g} dB(A))",
                 lambda k=k: p.solve(limits=[lim for j, lim in enumerate(p.limits) if j != k]))
                for k, m in enumerate(models)]
    variants += [("the squeal share (not raised)", lambda: p.solve(limits=noise_only)),
                 (f"the per-band cap ({100 * est.cfg.advice_max_share:g} %)", lambda: p.solve(cap=np.ones_like(p.cap))),
                 (f"the band width ({est.cfg.advice_band_kmh:g} km/h; halved)",
                  lambda: _halved(est, consequences, pool)),
                 (ALL, lambda: p.solve(cap=np.ones_like(p.cap), limits=[]))]
    relaxed = []
    for name, solve in variants:
        plan = solve()
        relaxed.append(Relaxed(name, plan.peak_growth < base.peak_growth * (1.0 - BINDS), factor(plan)))
    mean_s, worst_s = timetable_cost(p, base, est.cfg.advice_length_m)
    return AdviceExplained(factor(base), relaxed, est.cfg.advice_length_m, mean_s, worst_s)


def _halved(est: CorrugationEstimator, consequences: Consequences, pool: Executor | None) -> SpeedPlan:
    return advice_problem(est, consequences, pool, band_kmh=0.5 * est.cfg.advice_band_kmh).solve()


def timetable_cost(p: AdviceProblem, plan: SpeedPlan, length_m: float) -> tuple[float, float]:
    """Mean extra running time per train over length_m [s] (pass-weighted, advised less current, at
    the band centres) and the worst (a used band's lower edge against its class's mean speed)."""
    pace = np.where(p.allowed, length_m / np.where(p.allowed, p.centres, 1.0), 0.0)  # (C, S) [s]
    mean_s = float(p.pass_weight @ ((plan.share - p.current) * pace).sum(axis=1))
    used = p.allowed & (plan.share > 1e-6)
    slowest = np.where(used, length_m / np.where(used, np.maximum(p.low, MIN_SPEED_MPS), 1.0), -np.inf).max(axis=1)
    worst_s = float(np.max(slowest - length_m / p.mean))
    return mean_s, worst_s
