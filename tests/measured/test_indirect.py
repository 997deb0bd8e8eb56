"""Indirect rail roughness from measured pass-by noise (rail_monitor.measured.indirect): the fit
on a synthetic mix of classes, and on a simulated station measuring a rail that corrugated 3x
faster than the model's, against that rail's true roughness (an independent state)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rail_monitor.measured.indirect import MIN_PASSES, indirect_rail_roughness


def test_the_fit_recovers_a_rail_energy_change_from_a_mix_of_wheels():
    # Two classes: disc-braked (rail 90 % of the combined roughness) and tread-braked (30 %). The
    # rail's energy is 2x the model's (+3.01 dB) in every band; residuals = 10 lg(1 + s x) + noise.
    rng = np.random.default_rng(8)
    n, band_hz = 400, np.array([500.0, 630.0, 800.0])
    speed = rng.uniform(15.0, 25.0, n)
    share = np.where(rng.random(n) < 0.5, 0.9, 0.3)[:, None] * np.ones(len(band_hz))
    residual = 10 * np.log10(1 + share * 1.0) + rng.normal(0.0, 0.5, share.shape)
    bands = np.geomspace(0.0158, 0.05, 6)
    got = indirect_rail_roughness(residual, share, speed, band_hz, bands, np.zeros(len(bands)), 0.0)
    ok = got.passes >= MIN_PASSES
    assert ok.sum() >= 4
    # 10 lg 2 within 4 standard errors of the fit (the noise's energy mean biases up by ~0.06 dB)
    assert np.all(np.abs(got.level_db[ok] - 10 * math.log10(2.0)) <= 4 * got.sd_db[ok] + 0.1)
    assert np.all(got.sd_db[ok] < 0.5) and np.all(np.isnan(got.level_db[~ok]))


def test_a_simulated_station_reads_the_true_rail_roughness(site_values):
    from rail_monitor.batch.run import run_models
    from rail_monitor.core.simulator_params import simulator_config
    from rail_monitor.core.site import site_from_values
    from rail_monitor.noise.config import noise_config
    from rail_monitor.noise.predict import RollingNoiseModel
    from rail_monitor.noise.records import Corrugation
    from rail_monitor.simulation.measurements import simulate_measurements
    from rail_monitor.simulation.simulator import simulate
    from rail_monitor.simulation.surveys import true_estimator
    from rail_monitor.whatif.roughness import indirect_of_run

    site = site_from_values(site_values)
    passes = simulate(site, simulator_config({**site_values, "simulator.days": 300.0, "simulator.seed": 20}))
    truth = run_models(passes, site_values, estimator=true_estimator(site, site_values, 3.0))
    p = truth.noise["cnossos"]
    station = simulate_measurements(truth.accepted, p.lp_db, p.lpaeq_tp_dba, p.lpafmax_dba, p.tel_dba,
                                    p.band_centre_hz, (7.5, 1.2), seed=3, defective=0)
    result = run_models(passes, site_values, measurements=station.measurements)
    ind = indirect_of_run(result, site_values, 28.0)
    model = RollingNoiseModel(site, noise_config(site_values))
    te = truth.estimator
    true_db = np.interp(te.bands, model.grid, model.rail_roughness_db(
        Corrugation(te.bands, te.amplitude, te.grinding_amplitude)))
    ok = np.isfinite(ind.level_db)
    assert ok.sum() >= 15
    assert np.max(true_db[ok] - ind.model_db[ok]) > 10  # the model is far off where the truth corrugated
    # within one standard uncertainty (2 dB, the prediction's) in every band, 1.1 dB at worst
    assert np.all(np.abs(ind.level_db[ok] - true_db[ok]) <= ind.sd_db[ok])
    assert np.max(np.abs(ind.level_db[ok] - true_db[ok])) < 1.5
    with pytest.raises(Exception, match="no measured pass"):
        indirect_of_run(run_models(passes, site_values), site_values, 28.0)
