"""A site's grinding outlook: the forecast now, the forecast of a rail ground now, and the visits'
costs from the site's economics parameters."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.passes import accepted_passes
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.surveys import apply_grinding
from rail_monitor.economics.config import economics_config
from rail_monitor.economics.outlook import site_outlook
from rail_monitor.engine.site_config import SiteConfig


@pytest.fixture(scope="module")
def after_sample(sample_passes):
    from rail_monitor.site_file import load_parameter_file

    from conftest import SITE_FILE

    cfg = SiteConfig.from_values(load_parameter_file(SITE_FILE))
    est = CorrugationEstimator(cfg.site, cfg.corrugation)
    est.advance(accepted_passes(sample_passes, cfg.site))
    return est, cfg


def test_the_cycle_is_the_forecast_of_the_rail_ground_now(after_sample):
    """The cycle (forecast_interval(after_grinding=True)) is, to the bit, the forecast the state
    has once a grinding event without a spectrum is applied at its newest pass: the same traffic,
    posterior and post-grinding roughness reach the interval by the other path (surveys.apply_grinding)."""
    est, cfg = after_sample
    outlook = site_outlook(est, cfg.economics)
    np.testing.assert_array_equal(outlook.due_days, est.forecast_interval().days)
    ground = copy.deepcopy(est)
    apply_grinding(ground, est.newest_ns)
    np.testing.assert_array_equal(outlook.cycle_days, ground.forecast_interval().days)
    assert np.all(np.diff(outlook.cycle_days) >= 0) and np.all(np.diff(outlook.due_days) >= 0)
    assert outlook.cycle_days[1] > outlook.due_days[1]   # the sample's rail has grown since its last grinding


def test_visit_costs_and_cost_per_year(after_sample):
    """A visit: fixed part + passes x length x (pass + rail life); a corrective visit makes the late passes;
    the cost per year is a preventive visit per cycle, its P10 from the cycle's P90."""
    est, _ = after_sample
    cfg = economics_config({"economics.grind_length_m": 400.0, "economics.passes_per_grind": 2,
                            "economics.late_passes_per_grind": 5, "economics.cost_per_pass_m": 10.0,
                            "economics.visit_cost": 3000.0, "economics.rail_cost_per_pass_m": 2.5})
    o = site_outlook(est, cfg)
    assert o.visit_cost == 3000.0 + 2 * 400.0 * 12.5 and o.late_visit_cost == 3000.0 + 5 * 400.0 * 12.5
    np.testing.assert_allclose(o.cost_per_year(), o.visit_cost * 365.25 / o.cycle_days[::-1], rtol=1e-15)
    with pytest.raises(ConfigError, match="late_passes_per_grind"):
        economics_config({"economics.passes_per_grind": 3, "economics.late_passes_per_grind": 2})
