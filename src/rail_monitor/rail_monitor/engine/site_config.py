"""A site's parameters parsed once: the Site and every model's checked config (no rclpy).

The flat values of a site file (rail_monitor.site_file) go through each section's strict loader
once, here; batch mode, the report and the what-if questions take the configs from this object
instead of parsing the values again.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

from rail_monitor.alerts.config import AlertConfig, alert_config
from rail_monitor.core.node_params import STAMP_SPECS, StampParams
from rail_monitor.core.params import resolve, section, values_of
from rail_monitor.core.site import Site, site_from_values
from rail_monitor.corrugation.config import CorrugationConfig, corrugation_config
from rail_monitor.economics.config import EconomicsConfig, economics_config
from rail_monitor.measured.config import ResidualConfig, residual_config
from rail_monitor.noise.config import NoiseConfig, noise_config
from rail_monitor.squeal.config import SquealConfig, squeal_config


@dataclass(frozen=True)
class SiteConfig:
    """A site and its models' configs (units as in each section's specs)."""

    values: Mapping[str, Any]       # the flat values parsed (read-only), for what a report or bag shows
    site: Site
    corrugation: CorrugationConfig
    noise: NoiseConfig
    squeal: SquealConfig
    residual: ResidualConfig
    alerts: AlertConfig             # with the corrugation lead time
    stamps: StampParams
    economics: EconomicsConfig

    @classmethod
    def from_values(cls, values: Mapping[str, Any]) -> SiteConfig:
        """Every section of flat dotted values checked (ConfigError naming the first bad one)."""
        corrugation = corrugation_config(values)
        return cls(values=MappingProxyType(dict(values)), site=site_from_values(values), corrugation=corrugation,
                   noise=noise_config(values), squeal=squeal_config(values), residual=residual_config(values),
                   alerts=alert_config(values, corrugation.lead_time_days),
                   stamps=values_of(StampParams, resolve(STAMP_SPECS, section(values, "stamps."), "stamps.",
                                                         strict=True)),
                   economics=economics_config(values))
