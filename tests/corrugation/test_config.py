"""The corrugation parameters (rail_monitor.corrugation.config)."""

from __future__ import annotations

import pytest

from rail_monitor.core.errors import ConfigError
from rail_monitor.corrugation.config import corrugation_config


def test_bad_configuration_is_refused():
    with pytest.raises(ConfigError, match="shortest_wavelength_m"):
        corrugation_config({"corrugation.shortest_wavelength_m": 2.0, "corrugation.longest_wavelength_m": 1.0})
    with pytest.raises(ConfigError, match=r"corrugation\.k_b\.dyr"):
        corrugation_config({"corrugation.k_b.dyr": 1e-5})
