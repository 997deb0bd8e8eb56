"""A site's options (economics.options): the friction modifier's cycle against the same history
run under a modifier, the options priced on the sample, and the season's dry days moved with their
growth."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rail_monitor.advice.consequences import Consequences
from rail_monitor.core.friction import FRICTION_DRY, FRICTION_MODIFIER
from rail_monitor.core.passes import accepted_passes
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.corrugation import forecast as fcst
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.economics.config import economics_config
from rail_monitor.economics.options import dry_as_modifier, site_options, squeal_shares
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.noise.predict import RollingNoiseModel


@pytest.fixture(scope="module")
def sample_site(sample_passes):
    from rail_monitor.site_file import load_parameter_file

    from conftest import SITE_FILE

    cfg = SiteConfig.from_values(load_parameter_file(SITE_FILE))
    return cfg, accepted_passes(sample_passes, cfg.site)


def _run(cfg: SiteConfig, passes) -> CorrugationEstimator:
    est = CorrugationEstimator(cfg.site, cfg.corrugation)
    est.advance(passes)
    return est


def test_the_modifier_cycle_is_the_history_run_under_a_modifier(sample_site):
    """Independent path: the sample's last 150 days (under a year: the recent-traffic forecast) run
    again with every dry pass in the friction-modifier state give, to 1e-9 relative, the cycle the
    option forecasts from the history as it ran (each dry pass's growth re-evaluated in that state,
    its contact regime included), over the same K_b posterior draws."""
    cfg, passes = sample_site
    recent = passes.take(passes.stamp_ns >= passes.stamp_ns.max() - 150 * NS_PER_DAY)
    dry = np.asarray(recent.friction_state) == FRICTION_DRY
    assert 0.2 < dry.mean() < 1.0
    treated = dataclasses.replace(recent, friction_state=np.where(dry, FRICTION_MODIFIER, recent.friction_state))
    as_ran, under_modifier = _run(cfg, recent), _run(cfg, treated)
    option = as_ran.forecast_interval(after_grinding=True, dry_as_modifier=dry_as_modifier(as_ran))
    np.testing.assert_allclose(option.days, under_modifier.forecast_interval(after_grinding=True).days, rtol=1e-9)
    assert option.days[1] > as_ran.forecast_interval(after_grinding=True).days[1]


def test_the_options_priced_on_the_sample(sample_site):
    """The three options on the sample's state: speed control's cycle is grinding's times its
    interval factor (at least 1: the advice never raises the peak growth); the friction modifier
    lengthens the cycle (K_b 3e-6 against 1e-5 dry, the model's defaults) and squeals on no more
    passes; running costs as given."""
    cfg, passes = sample_site
    est = _run(cfg, passes)
    econ = economics_config({"economics.options": ["grind", "speed_control", "friction_modifier"],
                             "economics.speed_control_cost_per_year": 50.0,
                             "economics.applicator_cost_per_year": 400.0})
    cons = Consequences(cfg.site, RollingNoiseModel(cfg.site, cfg.noise), cfg.squeal)
    grind, speed, modifier = site_options(est, econ, cons)
    assert [grind.name, speed.name, modifier.name] == ["grind", "speed_control", "friction_modifier"]
    np.testing.assert_array_equal(grind.cycle_days, est.forecast_interval(after_grinding=True).days)
    factor = speed.cycle_days / grind.cycle_days
    assert np.allclose(factor, factor[0], rtol=1e-12) and factor[0] >= 1.0
    assert f"interval x{factor[0]:.2f}" in speed.effects and "running time" in speed.effects
    assert speed.cost_per_year == 50.0 and modifier.cost_per_year == 400.0
    assert modifier.cycle_days[1] > grind.cycle_days[1]
    now, treated = squeal_shares(est, cons)
    assert 0.0 <= treated <= now <= 1.0


def test_the_season_moves_its_dry_days_with_their_growth():
    """with_friction_modifier on random growth: the dry slot empties into the modifier's; a modifier
    halving each dry component's growth moves half the season's dry growth (in K_b units, the
    season being per unit K_b), and the other states are untouched."""
    rng = np.random.default_rng(4)
    growth, season = rng.normal(size=(4, 3, 5)), rng.normal(size=(20, 4, 3, 5))
    k_b = np.array([1e-5, 5e-6, 3e-6, 2e-6])
    dry, fm = FRICTION_DRY - 1, FRICTION_MODIFIER - 1
    g, s = fcst.with_friction_modifier(growth, 0.5 * growth[dry], season, k_b)
    assert np.all(g[dry] == 0) and np.all(s[:, dry] == 0)
    np.testing.assert_allclose(g[fm], growth[fm] + 0.5 * growth[dry], rtol=1e-14)
    np.testing.assert_allclose(s[:, fm] * k_b[fm], season[:, fm] * k_b[fm] + 0.5 * season[:, dry] * k_b[dry],
                               rtol=1e-12)
    for f in (1, 3):
        np.testing.assert_array_equal(g[f], growth[f])
        np.testing.assert_array_equal(s[:, f], season[:, f])
