"""What a site may do besides grinding on its forecast, priced for a programme: hold the speed
advice, or apply a friction modifier where the rail runs dry. Each is an economics.outlook.Option
in force from the site's next visit: its grinding cycle with the forecast's uncertainty, its
running cost (economics.* site parameters), and its other effects.

- grind: the cycle of CorrugationEstimator.forecast_interval(after_grinding=True).
- speed_control: that cycle times the advice's grinding interval factor (advice.plan.advise, the
  UQ paper's section 2.1: the peak growth of the current over the advised speed distribution),
  with the advice's change of rolling noise and squealing passes, and its timetable cost
  (advice.explain.timetable_cost). Where no advice fits its limits, the factor is 1.
- friction_modifier: the cycle with each recent dry pass's growth as the same pass in the
  friction-modifier state (its contact regime and K_b), drawn over the site's friction-modifier K_b posterior (the prior
  where the site never ran one), and the passes at squeal risk with the rail so treated. Field
  data for scale: at Bilbao, corrugation grew 0.1 to 0.5 mm in 18 months without a modifier and
  about none with one, and squeal fell 6.3-22.8 dB(A) (D. T. Eadie and M. Santoro, "Top-of-rail
  friction control for curve noise mitigation and corrugation rate reduction", J. Sound Vib.
  293 (2006) 747-757). Rolling noise is not changed: the rail runs the same roughness range,
  ground less often.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rail_monitor.advice.consequences import Consequences
from rail_monitor.advice.explain import timetable_cost
from rail_monitor.advice.plan import advice_problem, advise
from rail_monitor.core.contact import contact_state_of
from rail_monitor.core.friction import FRICTION_DRY, FRICTION_MODIFIER
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.history import COLUMNS, KeptPasses
from rail_monitor.economics.config import EconomicsConfig
from rail_monitor.economics.outlook import Option, SiteOutlook, site_outlook


def configured_outlook(est: CorrugationEstimator, cfg: EconomicsConfig,
                       consequences: Callable[[], Consequences]) -> SiteOutlook:
    """The site's outlook with the options its economics.options offer priced (grinding alone: none,
    and consequences is not called)."""
    options = site_options(est, cfg, consequences()) if cfg.options != ["grind"] else ()
    return site_outlook(est, cfg, options)


def site_options(est: CorrugationEstimator, cfg: EconomicsConfig, consequences: Consequences) -> tuple[Option, ...]:
    """The site's options (cfg.options, in the order of economics.config.OPTIONS) priced on its state."""
    cycle = est.forecast_interval(after_grinding=True).days.astype(float)
    out = []
    for name in cfg.options:
        if name == "grind":
            out.append(Option("grind", cycle))
        elif name == "speed_control":
            out.append(speed_control(est, cycle, cfg.speed_control_cost_per_year, consequences))
        else:
            out.append(friction_modifier(est, cfg.applicator_cost_per_year, consequences))
    return tuple(out)


def speed_control(est: CorrugationEstimator, cycle_days: np.ndarray, cost_per_year: float,
                  consequences: Consequences) -> Option:
    """The grind cycle stretched by the advice's interval factor, with its other effects."""
    try:
        p = advice_problem(est, consequences)
        a = advise(est, consequences, problem=p)
    except ValueError as err:
        return Option("speed_control", cycle_days, cost_per_year, f"no speed advice fits ({err}): interval x1.00")
    mean_s, worst_s = timetable_cost(p, p.solve(), est.cfg.advice_length_m)
    noise = ", ".join(f"{m} {d:+.1f}" for m, d in zip(a.noise_model, a.noise_change(), strict=True))
    return Option("speed_control", cycle_days * a.grinding_interval_factor, cost_per_year,
                  f"interval x{a.grinding_interval_factor:.2f}; rolling noise {noise} dB(A); squealing passes "
                  f"{100 * a.squeal_share_current:.1f} -> {100 * a.squeal_share_recommended:.1f} %; running time "
                  f"{mean_s:+.1f} s per train (at most {worst_s:+.1f} s) over {est.cfg.advice_length_m:g} m")


def friction_modifier(est: CorrugationEstimator, cost_per_year: float, consequences: Consequences) -> Option:
    """The grind cycle with a friction modifier where the rail was dry, with the squealing passes."""
    cycle = est.forecast_interval(after_grinding=True, dry_as_modifier=dry_as_modifier(est)).days.astype(float)
    base = est.forecast_interval(after_grinding=True).days[1]
    now, treated = squeal_shares(est, consequences)
    return Option("friction_modifier", cycle, cost_per_year,
                  f"interval x{cycle[1] / base:.2f} (P50); squealing passes {100 * now:.1f} -> {100 * treated:.1f} %; "
                  "rolling noise unchanged (the same roughness range, ground less often)")


def dry_as_modifier(est: CorrugationEstimator) -> np.ndarray:
    """The recent dry passes' log growth as the same passes in the friction-modifier state, per
    axle pass of all kept passes (B, P): the modifier's creep curve sets each one's contact regime
    again (core.contact), its K_b its wear."""
    k = est.kept
    dry = k.friction == FRICTION_DRY
    names = np.asarray(est.tables.classes, object)[k.class_idx[dry]]
    treated = np.full(int(dry.sum()), FRICTION_MODIFIER)
    regime = contact_state_of(est.site, names, treated, k.load[dry], k.creepage[dry], k.speed[dry]).regime
    growth = est.tables.at(k.class_idx[dry], treated, regime, k.speed[dry], k.axles[dry], est.engine)
    return growth.sum(axis=0) / max(int(k.axles.sum()), 1)


def squeal_shares(est: CorrugationEstimator, consequences: Consequences) -> tuple[float, float]:
    """Share of the kept passes at squeal risk medium or above [-]: as they ran, and with each dry
    pass in the friction-modifier state."""
    k = est.kept
    treated = KeptPasses(**{c: getattr(k, c) for c in COLUMNS if c != "friction"},
                         friction=np.where(k.friction == FRICTION_DRY, FRICTION_MODIFIER, k.friction))
    out = []
    for kept in (k, treated):
        shares = [consequences.squeal_share(kept, est.tables.classes[i], int(i), None)[0] * np.mean(k.class_idx == i)
                  for i in np.unique(k.class_idx)]
        out.append(float(np.sum(shares)))
    return out[0], out[1]
