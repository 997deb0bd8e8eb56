"""The one strict configuration path (rail_monitor.site_file): every name of a site file is checked
against every section's specs, and a typo is refused with one line naming it and the nearest name."""

from __future__ import annotations

import re

import pytest
import yaml

from rail_monitor.core.errors import ConfigError
from rail_monitor.site_file import known_names, load_parameter_file, load_site

from conftest import SITE_FILE


def _with(tmp_path, dotted: str, value) -> str:
    """The shipped site file with one more (dotted) parameter."""
    doc = yaml.safe_load(SITE_FILE.read_text())
    node = doc["/**"]["ros__parameters"]
    *parents, leaf = dotted.split(".")
    for p in parents:
        node = node.setdefault(p, {})
    node[leaf] = value
    path = tmp_path / "site.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


@pytest.mark.parametrize(("typo", "nearest"), [
    ("vehicle.emu.wheel_diamter_m", "vehicle.emu.wheel_diameter_m"),   # a vehicle class
    ("simulator.dayz", "simulator.days"),                              # the simulator
    ("curve_radius", "curve_radius_m"),                                # the top level
    ("corrugation.k_b.dyr", "corrugation.k_b.dry"),                    # a model section
    ("alerts.noise_limit_db", "alerts.noise_limit_dba"),
    ("track.pad_stifness_npm", "track.pad_stiffness_npm"),
    ("checkpoint_every_pass", "checkpoint_every_passes"),              # a node's own parameter
])
def test_a_typo_anywhere_is_refused_with_the_nearest_known_name(tmp_path, typo, nearest):
    with pytest.raises(ConfigError) as err:
        load_parameter_file(_with(tmp_path, typo, 1.0))
    text = str(err.value)
    assert "\n" not in text and f"unknown parameter '{typo}'" in text and f"did you mean '{nearest}'?" in text


def test_a_name_far_from_every_known_one_gets_no_suggestion(tmp_path):
    with pytest.raises(ConfigError, match=r"unknown parameter 'zzzzzz'$"):
        load_parameter_file(_with(tmp_path, "zzzzzz", 1))


def test_the_shipped_file_passes_and_every_section_is_known():
    values = load_parameter_file(SITE_FILE)
    names = known_names(values)
    assert set(values) <= names
    for prefix in ("contact.", "track.", "corrugation.", "squeal.", "noise.", "alerts.", "simulator.",
                   "vehicle.freight."):
        assert any(n.startswith(prefix) for n in names), prefix
    assert {"use_sim_time", "checkpoint_path", "state_wait_s", "max_batch", "rate", "output"} <= names
    assert load_site(SITE_FILE).site_id == "curve_250"


def test_unreadable_or_misshapen_files_are_one_line(tmp_path):
    missing = tmp_path / "none.yaml"
    with pytest.raises(ConfigError, match=re.escape(f"{missing}: no such file")):
        load_parameter_file(missing)
    flat = tmp_path / "flat.yaml"
    flat.write_text("site_id: x\n")
    with pytest.raises(ConfigError, match="no 'ros__parameters' mapping"):
        load_parameter_file(flat)
