"""The whole measurement loop on a simulated year (issue 20's bar): a true rail whose K_b is 3x the
configured one, surveyed every 90 days with 1 dB per band, and a noise station measuring every
pass of that rail (with 4 wheel-flat vehicles in the fleets), all through one batch run: K_b is
within 20 % of the truth after the second survey, the forecast's P10-P90 brackets the true
grinding date after the third and fourth, every defective vehicle is alerted by name, and at most
1 % of passes are flagged falsely."""

from __future__ import annotations

import numpy as np

from rail_monitor.alerts.config import KIND_WHEEL_DEFECT, alert_config
from rail_monitor.alerts.manager import wheel_defect_score
from rail_monitor.batch.run import run_models
from rail_monitor.core.passes import rejection_reasons, with_class_defaults
from rail_monitor.core.simulator_params import simulator_config
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.surveys import KIND_SURVEY, MaintenanceEvent
from rail_monitor.engine.corrugation_site import advance_with_events
from rail_monitor.simulation.measurements import simulate_measurements
from rail_monitor.simulation.simulator import simulate
from rail_monitor.simulation.surveys import simulate_surveys, true_estimator


def test_a_simulated_year_closes_the_loop(site, site_values):
    # Seed 20, the first of the studies in docs/models.md; the station's seed 20 too.
    passes = simulate(site, simulator_config({**site_values, "simulator.days": 365.0, "simulator.seed": 20}))
    series = simulate_surveys(site, site_values, passes, 3.0, 90.0, 1.0, 120)
    on_truth = run_models(passes, site_values, estimator=true_estimator(site, site_values, 3.0))
    p = on_truth.noise["cnossos"]
    station = simulate_measurements(on_truth.accepted, p.lp_db, p.lpaeq_tp_dba, p.lpafmax_dba, p.tel_dba,
                                    p.band_centre_hz, (7.5, 1.2), seed=20, squealing=on_truth.squeal["risk"] >= 2)
    events = [MaintenanceEvent(int(s), KIND_SURVEY, series.wavelength_m, series.amplitude_m[k])
              for k, s in enumerate(series.stamp_ns.tolist())]
    result = run_models(passes, site_values, events=events, measurements=station.measurements)

    traj = result.trajectory
    after_second = traj.constants_at(int(np.searchsorted(traj.stamp_ns, series.stamp_ns[1], side="right")))
    np.testing.assert_allclose(after_second.k_b, series.true_k_b, rtol=0.2)

    ok = with_class_defaults(passes.take(rejection_reasons(passes, site) == ""), site)
    for k in (2, 3):  # the interval on the state just after the third and the fourth survey
        est = CorrugationEstimator(site, corrugation_config(site_values))
        advance_with_events(est, ok.take(ok.stamp_ns <= series.stamp_ns[k]), events[: k + 1])
        due = est.forecast_interval().due_ns
        assert due[0] <= series.true_grinding_ns <= due[2], (k, due, series.true_grinding_ns)

    cfg = alert_config(site_values, 60.0)
    res = [r for r in result.residuals if r.model == cfg.residual_model]
    assert len(res) == len(station.measurements)
    flagged = np.array([wheel_defect_score(r, cfg.wheel_defect_vehicle_db) >= cfg.wheel_defect_raise_db for r in res])
    defective = np.array([bool(set(r.vehicle_id) & station.defective) for r in res])
    assert (flagged & ~defective).sum() <= 0.01 * len(res)
    raised = {a.key for a in result.alerts if a.kind == KIND_WHEEL_DEFECT and a.active}
    assert {f"vehicle {v}" for v in station.defective} <= raised
