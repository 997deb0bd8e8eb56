"""The site's grinding cost parameters (``economics.`` in a site file).

A visit of the grinding train costs its fixed part (possession, mobilisation, travel) plus, per
grinding pass over the ground length, the pass itself and the rail life the pass removes. A
preventive visit, made before any band passes its intervention threshold, makes fewer passes
than a corrective one made after: grinding found late needs more metal removed (docs/models.md,
"Grinding economics"). No published unit cost could be cited, so the defaults are neutral: the
cost unit is one grinding pass over one metre, fixed costs and rail life count only when given.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, section_values

OPTIONS = ("grind", "speed_control", "friction_modifier")

ECONOMICS_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("grind_length_m", 500.0, "Length of track a visit grinds (the corrugated curve with its run-off) "
              "[m].", 1.0, 1.0e5),
    ParamSpec("passes_per_grind", 1, "Grinding passes of a preventive visit, made before any band passes its "
              "threshold [-].", 1, 50),
    ParamSpec("late_passes_per_grind", 3, "Grinding passes of a corrective visit, made after a band passed its "
              "threshold [-].", 1, 50),
    ParamSpec("cost_per_pass_m", 1.0, "Cost of one grinding pass over one metre [cost unit/m] (the default "
              "makes the cost unit a pass-metre).", 0.0, 1.0e9),
    ParamSpec("visit_cost", 0.0, "Fixed cost of a visit: possession, mobilisation and travel [cost unit] "
              "(0: not counted).", 0.0, 1.0e12),
    ParamSpec("rail_cost_per_pass_m", 0.0, "Rail life one grinding pass consumes, per metre [cost unit/m]: the "
              "renewal cost per metre times the depth a pass removes over the head's wear allowance (0: not "
              "counted).", 0.0, 1.0e9),
    ParamSpec("options", ["grind"], "What a programme may choose at this site: grind on its forecast, and "
              "speed_control (the speed advice in force from its first visit) or friction_modifier (a trackside "
              "applicator where the rail runs dry, from its first visit) where the site can take them.",
              choices=OPTIONS),
    ParamSpec("speed_control_cost_per_year", 0.0, "Running cost of holding the advised speeds: signage, driver "
              "advice, timetable work [cost unit/year] (0: none counted).", 0.0, 1.0e12),
    ParamSpec("applicator_cost_per_year", 0.0, "Running cost of a trackside friction-modifier applicator: the "
              "unit over its life, product, refilling and maintenance [cost unit/year] (must be given to offer "
              "friction_modifier).", 0.0, 1.0e12),
)


@dataclass(frozen=True)
class EconomicsConfig:
    """The site's grinding costs (names and units as in ECONOMICS_SPECS)."""

    grind_length_m: float
    passes_per_grind: int
    late_passes_per_grind: int
    cost_per_pass_m: float
    visit_cost: float
    rail_cost_per_pass_m: float
    options: list[str]
    speed_control_cost_per_year: float
    applicator_cost_per_year: float

    def visit(self, late: bool = False) -> float:
        """Cost of one visit [cost unit]: preventive, or corrective (late)."""
        passes = self.late_passes_per_grind if late else self.passes_per_grind
        return self.visit_cost + passes * self.grind_length_m * (self.cost_per_pass_m + self.rail_cost_per_pass_m)


def economics_config(values: Mapping[str, Any], prefix: str = "economics.") -> EconomicsConfig:
    """Checked grinding cost parameters from flat parameter values (keys under prefix)."""
    cfg = section_values(EconomicsConfig, ECONOMICS_SPECS, values, prefix)
    if cfg.late_passes_per_grind < cfg.passes_per_grind:
        raise ConfigError(f"parameter '{prefix}late_passes_per_grind' is below '{prefix}passes_per_grind': a "
                          "corrective grind removes at least what a preventive one does")
    if not cfg.options or len(set(cfg.options)) < len(cfg.options):
        raise ConfigError(f"parameter '{prefix}options' must name each option at most once, and at least one")
    if "friction_modifier" in cfg.options and cfg.applicator_cost_per_year == 0:
        raise ConfigError(f"parameter '{prefix}options' offers friction_modifier: give "
                          f"'{prefix}applicator_cost_per_year' (an applicator is never free)")
    return cfg
