"""Repeat squealers (rail_monitor.alerts.squealers, issue 55): the vehicles heard squealing far more
often than the site's passes alike are named, the others never; a reprofiled wheel clears."""

from __future__ import annotations

import numpy as np

from rail_monitor.alerts.config import KIND_SQUEAL_OFFENDER
from rail_monitor.alerts.squealers import RepeatSquealers
from rail_monitor.batch.run import run_models
from rail_monitor.core.simulator_params import simulator_config
from rail_monitor.core.site import site_from_values
from rail_monitor.simulation.measurements import station_on_true_rail
from rail_monitor.simulation.simulator import simulate
from rail_monitor.site_file import load_parameter_file

from conftest import SITE_FILE


def test_a_vehicle_that_squeals_on_every_train_is_named_and_cleared_once_it_stops():
    """40 vehicles in consists of 4 drawn at random; passes squeal at 10 % (risk 1) and 60 % (risk 3)
    as the site's share; vehicle V7 makes its train squeal every time for 300 passes, then never.
    It is named, no other is, and once its window holds only quiet passes it is cleared."""
    rng = np.random.default_rng(55)
    s = RepeatSquealers(window=50, min_passes=10, raise_p=1e-5, clear_p=0.01)
    raised, cleared = [], []
    for i in range(1200):
        consist = tuple(f"V{k}" for k in rng.choice(40, 4, replace=False))
        risk = int(rng.choice([1, 3]))
        squealed = rng.random() < (0.1 if risk == 1 else 0.6)
        if "V7" in consist and i < 300:
            squealed = True
        for v in s.add(i, f"T{i}", consist, squealed, risk):
            (raised if v.flagged else cleared).append(v.key)
    assert raised == ["vehicle V7"] and cleared == ["vehicle V7"]


def test_on_a_simulated_quarter_every_planted_squealer_is_named_and_no_other_vehicle():
    """90 days of the shipped site with a station measuring every pass (its fleets of 40 vehicles a
    class, consists re-formed per train, 2 % of flags wrong), two vehicles whose trains squeal on
    half their passes besides: batch mode's alerts name exactly those two."""
    values = load_parameter_file(SITE_FILE)
    values["simulator.days"] = 90.0
    table = simulate(site_from_values(values), simulator_config(values))
    station = station_on_true_rail(table, values, 1.0, int(values["simulator.seed"]), squealers=2)
    assert len(station.squealers) == 2
    result = run_models(table, values, measurements=station.measurements)
    named = {a.key for a in result.alerts if a.kind == KIND_SQUEAL_OFFENDER and a.active}
    assert named == {f"vehicle {v}" for v in station.squealers}
