"""The advice tests' fixtures: the corrugation tests' (the sample site, its growth tables, the
sample passes), and the sample's state with the site's consequences (world)."""

import pytest
from corrugation.conftest import sample, site_, tables  # noqa: F401  (fixtures)

from rail_monitor.advice.consequences import Consequences
from rail_monitor.core.passes import rejection_reasons, with_class_defaults
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.squeal.config import squeal_config


@pytest.fixture(scope="module")
def world(sample_passes):
    from rail_monitor.site_file import load_parameter_file, load_site

    from conftest import SITE_FILE

    site, values = load_site(SITE_FILE), load_parameter_file(SITE_FILE)
    cons = Consequences(site, RollingNoiseModel(site, noise_config(values)), squeal_config(values))
    est = CorrugationEstimator(site, corrugation_config(values))
    ok = rejection_reasons(sample_passes, site) == ""
    est.advance(with_class_defaults(sample_passes.take(ok), site))
    return site, values, cons, est
