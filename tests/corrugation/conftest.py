"""Shared fixtures and helpers of the corrugation tests: the sample site, its growth tables, the
sample passes."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.core.passes import FRICTION_DRY, PassTable, rejection_reasons, with_class_defaults
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.growth import GrowthTables


@pytest.fixture(scope="module")
def site_():
    from rail_monitor.site_file import load_site

    from conftest import SITE_FILE

    return load_site(SITE_FILE)


@pytest.fixture(scope="module")
def tables(site_):
    """The default configuration's growth tables (shared: building them takes about 2 s)."""
    return GrowthTables(site_, corrugation_config({}))


def _estimator(site_, tables, **values) -> CorrugationEstimator:
    cfg = corrugation_config({f"corrugation.{k}": v for k, v in values.items()})
    return CorrugationEstimator(site_, cfg, tables if not values else None)


def _passes(site_, speeds, friction=FRICTION_DRY, start_s=0.0, step_s=600.0, prefix="T") -> PassTable:
    v = np.asarray(speeds, float)
    n = len(v)
    return with_class_defaults(PassTable(
        stamp_ns=(1_790_000_000 + start_s + np.arange(n) * step_s).astype(np.int64) * 10**9,
        train_id=[f"{prefix}{i}" for i in range(n)], vehicle_class=["emu"] * n, vehicle_count=[4] * n,
        axle_count=[0] * n, speed_mps=v, angle_of_attack_rad=[0.0] * n, wheel_load_n=[0.0] * n,
        friction_state=np.broadcast_to(friction, n), train_length_m=[0.0] * n), site_)


@pytest.fixture(scope="module")
def sample(site_, sample_passes):
    return with_class_defaults(sample_passes.take(rejection_reasons(sample_passes, site_) == ""), site_)
