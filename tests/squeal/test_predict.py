"""Squeal at the site: the per-pass prediction (rail_monitor.squeal.predict) and its parameters."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.passes import FRICTION_DRY, FRICTION_MODIFIER, PassTable, rejection_reasons, with_class_defaults
from rail_monitor.core.site import site_from_values
from rail_monitor.models.squeal import REGIME_LIMIT_CYCLE, REGIME_STABLE
from rail_monitor.squeal.config import RISK_NONE, squeal_config
from rail_monitor.squeal.predict import predict


def _passes(site, aoa_mrad, friction=FRICTION_DRY, speed=19.0) -> PassTable:
    aoa = np.atleast_1d(np.asarray(aoa_mrad, float)) * 1e-3
    n = len(aoa)
    return with_class_defaults(PassTable(
        stamp_ns=np.arange(1, n + 1) * 10**9, train_id=[f"T{i}" for i in range(n)], vehicle_class=["emu"] * n,
        vehicle_count=[4] * n, axle_count=[0] * n, speed_mps=[speed] * n, angle_of_attack_rad=aoa,
        wheel_load_n=[0.0] * n, friction_state=np.broadcast_to(friction, n), train_length_m=[0.0] * n), site)


def test_site_onset_follows_the_rule_of_thumb(site, site_values):
    # docs/models.md, "Wheel squeal": squeal onset at an angle of attack of about 5-10 mrad (dry rail).
    cfg = squeal_config(site_values)
    aoa = np.linspace(0.5, 25, 50)
    pred = predict(cfg, site, _passes(site, aoa))
    onset = aoa[np.argmax(pred["unstable"])]
    assert 5.0 <= onset <= 10.0
    assert np.all(pred["unstable"][aoa > onset])
    assert np.all(pred["regime"][pred["unstable"]] == REGIME_LIMIT_CYCLE)


def test_friction_modifier_removes_squeal_and_its_benefit_is_in_the_field_range(site, site_values):
    cfg = squeal_config(site_values)
    fm = predict(cfg, site, _passes(site, [8, 12, 20], FRICTION_MODIFIER))
    assert np.all(fm["regime"] == REGIME_STABLE) and np.all(fm["risk"] == RISK_NONE)
    np.testing.assert_array_equal(fm["friction_modifier_benefit_db"], 0.0)
    # Eadie & Santoro (2006): 6.3-22.8 dB(A) less curve noise with a friction modifier. Dry
    # passes that squeal at 10-16 mrad land inside that range (against an 80 dB(A) background;
    # a 20 mrad pass would gain 25 dB, more than any site measured).
    dry = predict(cfg, site, _passes(site, [10, 12, 16]))
    assert np.all(dry["unstable"])
    assert np.all((dry["friction_modifier_benefit_db"] >= 6.3) & (dry["friction_modifier_benefit_db"] <= 22.8))
    assert np.all(np.diff(dry["level_dba"]) > 0)


def test_unknown_or_inconsistent_squeal_parameters_are_refused(site_values):
    with pytest.raises(ConfigError, match=r"squeal\.modal_mas"):
        squeal_config({**site_values, "squeal.modal_mas": 1.0})
    with pytest.raises(ConfigError, match="risk_high_dba"):
        squeal_config({**site_values, "squeal.risk_high_dba": 50.0})
    with pytest.raises(ConfigError, match=r"squeal\.poisson_ratio"):  # the contact is the site's, not squeal's
        squeal_config({**site_values, "squeal.poisson_ratio": 0.3})
    with pytest.raises(ConfigError, match=r"contact.poisson_ratio.*\[0, 0.5\]"):
        site_from_values({**site_values, "contact.poisson_ratio": 0.7})
    with pytest.raises(ConfigError, match=r"contact\.rail_head_radius"):
        site_from_values({**site_values, "contact.rail_head_radius": 0.3})


def test_batch_prediction_of_the_sample_is_fast_and_complete(site, site_values, sample_passes):
    table = sample_passes.take(rejection_reasons(sample_passes, site) == "")
    pred = predict(squeal_config(site_values), site, with_class_defaults(table, site))
    assert all(len(v) == len(table) for v in pred.values())
    assert np.all(np.isfinite(pred["velocity_amplitude_mps"]))
    # the sample's friction-modifier passes never squeal; some dry ones do
    fm = table.friction_state == FRICTION_MODIFIER
    assert not np.any(pred["unstable"][fm])
    dry = table.friction_state == FRICTION_DRY
    assert 0.05 < np.mean(pred["unstable"][dry]) < 0.6
    # a friction modifier on the squealing dry passes: their energy-mean level (with the background,
    # as a before/after survey at a site measures it) drops by an amount inside Eadie & Santoro's
    # 6.3-22.8 dB(A) site range (J. Sound Vib. 293 (2006) 747-757; mean 12 dB(A)), and by no more
    # than the unconditioned wheels allow, -10 lg(1 - friction_modifier_effectiveness)
    cfg = squeal_config(site_values)
    sq = dry & pred["unstable"]
    before = 10.0 * np.log10(10.0 ** (pred["level_dba"][sq] / 10.0) + 10.0 ** (cfg.background_level_dba / 10.0))
    after = before - pred["friction_modifier_benefit_db"][sq]
    reduction = 10.0 * np.log10(np.mean(10.0 ** (before / 10.0)) / np.mean(10.0 ** (after / 10.0)))
    assert 6.3 <= reduction <= 22.8
    assert np.all(pred["friction_modifier_benefit_db"] <= -10.0 * np.log10(1.0 - cfg.friction_modifier_effectiveness)
                  + 1e-9)


def test_the_risk_at_other_speeds_is_the_prediction_of_the_passes_run_at_them(site, site_values, sample_passes):
    # The advice's what-if (risk_at_speeds: each pass's contact once, then V0, Vc and u_s per speed)
    # against predict on copies of the passes at each speed, bit for bit.
    from dataclasses import replace

    from rail_monitor.squeal.predict import risk_at_speeds

    table = with_class_defaults(sample_passes.take(rejection_reasons(sample_passes, site) == ""), site)
    table = table.take(slice(0, 300))
    cfg, speeds = squeal_config(site_values), np.array([8.0, 14.0, 22.0, 31.0])
    got = risk_at_speeds(cfg, site, table, speeds[:, None])
    want = np.stack([predict(cfg, site, replace(table, speed_mps=np.full(len(table), v)))["risk"] for v in speeds])
    assert np.array_equal(got, want) and len(np.unique(want)) > 1
