"""Parameter specs (rail_monitor.core.params): coercion, ranges, choices, lists, strict sections."""

from __future__ import annotations

import math

import pytest

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, flatten, nearest_hint, refuse_unknown, resolve, section

SPEED = ParamSpec("speed_mps", 19.0, "Speed [m/s].", 0.5, 100.0)
MODE = ParamSpec("mode", "a", "Mode.", choices=("a", "b"))
LIST = ParamSpec("values", [1.0, 2.0], "Values [-].", 0.0, 10.0)


def test_values_are_checked_and_integers_accepted_where_a_float_is_declared():
    assert SPEED.check(20) == 20.0 and isinstance(SPEED.check(20), float)
    assert LIST.check([1, 2.5]) == [1.0, 2.5]
    assert MODE.check("b") == "b"
    for bad, match in ((0.1, "outside its range"), (math.inf, "finite"), (True, "must be float"),
                       ("20", "must be float")):
        with pytest.raises(ConfigError, match=match):
            SPEED.check(bad, "x.")
    with pytest.raises(ConfigError, match=r"'mode' = 'c' is not one of 'a', 'b'"):
        MODE.check("c")
    with pytest.raises(ConfigError, match="must be a list"):
        LIST.check(1.0)


def test_resolve_fills_defaults_and_a_strict_section_refuses_unknown_names():
    assert resolve((SPEED, MODE), {"mode": "b"}) == {"speed_mps": 19.0, "mode": "b"}
    with pytest.raises(ConfigError, match=r"unknown parameter 'sec\.speed_mp'; did you mean 'sec\.speed_mps'\?"):
        resolve((SPEED, MODE), {"speed_mp": 1.0}, where="sec.", strict=True)
    with pytest.raises(ConfigError, match=r"\(and 1 more\)"):
        refuse_unknown(["a_x", "b_y"], ["a"])
    assert nearest_hint("qqq", ["speed_mps"]) == ""


def test_nested_yaml_flattens_to_the_dotted_names_ros_uses():
    flat = flatten({"a": 1, "b": {"c": 2, "d": {"e": [3]}}})
    assert flat == {"a": 1, "b.c": 2, "b.d.e": [3]}
    assert section(flat, "b.") == {"c": 2, "d.e": [3]}


def _values_classes():
    from rail_monitor.alerts.config import ALERT_SPECS, AlertConfig
    from rail_monitor.core import node_params as n
    from rail_monitor.core.site import CONTACT_SPECS, WheelRailContact
    from rail_monitor.corrugation.config import CORRUGATION_SPECS, CorrugationConfig
    from rail_monitor.economics.config import ECONOMICS_SPECS, EconomicsConfig
    from rail_monitor.measured.config import RESIDUAL_SPECS, ResidualConfig
    from rail_monitor.noise.config import NOISE_SPECS, NoiseConfig
    from rail_monitor.squeal.config import SQUEAL_SPECS, SquealConfig

    return [(SquealConfig, SQUEAL_SPECS, ()), (CorrugationConfig, CORRUGATION_SPECS, ()),
            (NoiseConfig, NOISE_SPECS, ()), (ResidualConfig, RESIDUAL_SPECS, ()),
            (AlertConfig, ALERT_SPECS, (("lead_time_days", "float"),)),
            (WheelRailContact, CONTACT_SPECS, ()), (n.PublishParams, n.PUBLISH_SPECS, ()),
            (n.ReplayerParams, n.REPLAYER_SPECS, ()), (n.ModeParams, n.MODE_SPECS, ()),
            (n.RecorderParams, n.RECORDER_SPECS, ()), (n.MonitorParams, (*n.MONITOR_SPECS, n.SOURCE), ()),
            (n.StampParams, n.STAMP_SPECS, ()), (n.FoxgloveParams, n.FOXGLOVE_SPECS, ()),
            (n.EstimatorParams, n.ESTIMATOR_SPECS, ()), (EconomicsConfig, ECONOMICS_SPECS, ()),
            (n.PlannerParams, n.PLANNER_SPECS, ())]


def test_every_values_class_has_one_typed_field_per_spec():
    """The static config classes (fields an editor sees) hold exactly their specs, in spec order, with
    the specs' types: a spec added without its field, or a field of another type, fails here."""
    import dataclasses

    from rail_monitor.core.params import attribute

    classes = _values_classes()
    for klass, specs, extra in classes:
        want = [(attribute(s.name), str(s.annotation) if isinstance(s.default, list) else s.kind.__name__)
                for s in specs] + list(extra)
        got = [(f.name, f.type if isinstance(f.type, str) else f.type.__name__) for f in dataclasses.fields(klass)]
        assert got == want, klass.__name__
        assert klass.__dataclass_params__.frozen, klass.__name__
    assert len(classes) == 16
