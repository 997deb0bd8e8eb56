"""The traffic simulator: reproducible, and its statistics follow the site parameters."""

from __future__ import annotations

import numpy as np

from rail_monitor.core.passes import (
    FRICTION_CONTAMINATED,
    FRICTION_MODIFIER,
    FRICTION_WET,
    rejection_reasons,
)
from rail_monitor.core.simulator_params import simulator_config
from rail_monitor.core.timeutil import NS_PER_S
from rail_monitor.simulation.simulator import applicator_events, simulate


def _sim(site, values, **over):
    v = dict(values)
    v.update({f"simulator.{k}": x for k, x in over.items()})
    return simulate(site, simulator_config(v))


def test_same_seed_same_history_other_seed_differs(site, site_values):
    a, b = _sim(site, site_values, days=10.0), _sim(site, site_values, days=10.0)
    assert a.equals(b)
    assert not a.equals(_sim(site, site_values, days=10.0, seed=7))


def test_daily_count_matches_timetable(site, site_values):
    # Poisson arrivals: 300 days of a 96-train timetable give 96/day within 1 % (5 sigma ~ 1.2 %).
    t = _sim(site, site_values, days=300.0, leaf_season_start_doy=1, leaf_season_end_doy=1)
    expected = sum(site_values["simulator.trains_per_hour"])
    assert abs(len(t) / 300.0 - expected) / expected < 0.015
    assert np.all(np.diff(t.stamp_ns) >= 0)
    hours = (t.stamp_ns // (3600 * NS_PER_S)) % 24
    assert not np.isin(hours, [0, 1, 2, 3]).any()  # the timetable has no trains 00-04


def test_passes_are_valid_and_follow_class_parameters(site, site_values):
    t = _sim(site, site_values, days=60.0)
    assert (rejection_reasons(t, site) == "").all()
    for name, cls in site.vehicles.items():
        sel = t.vehicle_class == name
        s = t.speed_mps[sel]
        assert s.min() >= cls.speed_min_mps and s.max() <= cls.speed_max_mps
        assert abs(s.mean() - cls.speed_mean_mps) < 0.5
        assert abs(np.mean(sel) - cls.traffic_share) < 0.03
        # log-normal scatter with mean-preserving mu: mean AoA = f a / R within 5 %
        aoa = t.angle_of_attack_rad[sel]
        expect = site_values["simulator.curving_factor"] * cls.bogie_semi_wheelbase_m / site.curve_radius_m
        assert abs(aoa.mean() / expect - 1.0) < 0.05 + 3 * 0.35 / np.sqrt(sel.sum())
        assert np.all(t.axle_count[sel] == t.vehicle_count[sel] * cls.axles_per_vehicle)


def test_friction_process(site, site_values):
    t = _sim(site, site_values, days=90.0)
    day = (t.stamp_ns - t.stamp_ns.min()) / (86400 * NS_PER_S)
    fm_day = site_values["simulator.friction_modifier_start_day"]
    assert not np.any(t.friction_state[day < fm_day - 1] == FRICTION_MODIFIER)
    assert np.any(t.friction_state[day > fm_day + 1] == FRICTION_MODIFIER)
    # Leaf fall starts on 1 October (day 30 from 1 September): no contamination before.
    assert not np.any(t.friction_state[day < 29.9] == FRICTION_CONTAMINATED)
    wet = np.mean(t.friction_state == FRICTION_WET)
    assert 0.05 < wet < 0.30  # long-run 15 % wet hours, less where contamination takes precedence


def test_the_applicator_s_start_and_stop_are_the_history_s_events(site_values):
    """The friction modifier's service days as the applicator's events: a start on day 45 (no pass on
    the modifier before it), a stop only where service ends inside the history, none where it starts
    after the history's end or never."""
    from rail_monitor.core.friction import ACTION_START, ACTION_STOP
    from rail_monitor.core.timeutil import NS_PER_DAY

    cfg = simulator_config({**site_values, "simulator.days": 90.0})
    start, = applicator_events(cfg)
    assert (start.action, start.stamp_ns) == (ACTION_START, cfg.start_ns + 45 * NS_PER_DAY)
    ended = applicator_events(simulator_config({**site_values, "simulator.friction_modifier_end_day": 60.0}))
    assert [(e.action, e.stamp_ns - cfg.start_ns) for e in ended] == [(ACTION_START, 45 * NS_PER_DAY),
                                                                     (ACTION_STOP, 60 * NS_PER_DAY)]
    for over in ({"simulator.days": 30.0}, {"simulator.friction_modifier_start_day": -1.0}):
        assert applicator_events(simulator_config({**site_values, **over})) == []
