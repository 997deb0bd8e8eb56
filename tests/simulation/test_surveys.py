"""The survey loop end to end: a simulated year whose true K_b is 3x the configured one, surveyed
every 90 days with 1 dB per band, calibrates the estimator (rail_monitor.simulation.surveys,
rail_monitor.corrugation.surveys)."""

from __future__ import annotations

import numpy as np

from rail_monitor.core.passes import rejection_reasons, with_class_defaults
from rail_monitor.core.simulator_params import simulator_config
from rail_monitor.corrugation import surveys
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.simulation.simulator import simulate
from rail_monitor.simulation.surveys import simulate_surveys


def test_a_simulated_year_calibrates_k_b_and_brackets_the_grinding_date(site, site_values):
    # Seed 20, the first of the 12-seed study in docs/models.md ("Calibration"). After the second
    # survey (day 90) every friction state's K_b is within 20 % of the truth; after the third and
    # fourth, the P10-P90 interval of the grinding date contains the true rail's crossing.
    passes = simulate(site, simulator_config({**site_values, "simulator.days": 365.0, "simulator.seed": 20}))
    series = simulate_surveys(site, site_values, passes, 3.0, 90.0, 1.0, 120)
    truth = series.true_grinding_ns
    assert truth > 0
    est = CorrugationEstimator(site, corrugation_config(site_values))
    ok = with_class_defaults(passes.take(rejection_reasons(passes, site) == ""), site)
    done, covered = 0, []
    for k, stamp in enumerate(series.stamp_ns.tolist()):
        upto = int(np.searchsorted(ok.stamp_ns, stamp, side="right"))
        est.advance(ok.take(slice(done, upto)))
        done = upto
        fit = surveys.apply_survey(est, series.wavelength_m, series.amplitude_m[k], stamp)
        assert (fit is None) == (k == 0)
        if k == 1:
            np.testing.assert_allclose(est.k_b, series.true_k_b, rtol=0.2)
        if k in (2, 3) and stamp < truth:
            due = est.forecast_interval().due_ns
            covered.append(bool(due[0] <= truth <= due[2]))
    assert covered == [True, True]
