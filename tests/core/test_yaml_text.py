"""YAML a user wrote: every fault one line naming where (issue 52: deeply nested YAML gave a
RecursionError traceback through batch --site, rail-monitor site and pass_replayer --params-file)."""

from __future__ import annotations

import pytest

from rail_monitor.core.errors import ConfigError, InputError
from rail_monitor.core.yaml_text import MAX_DEPTH, load_yaml

from conftest import SITE_FILE, run_cmd

HOSTILE = {
    "lists nested 20,000 deep": "a: " + "[" * 20_000 + "]" * 20_000,
    "mappings nested 5,000 deep": "".join(f"{'  ' * 0}{{k{i}: " for i in range(5_000)) + "1" + "}" * 5_000,
    "lists nested one level too deep": "a: " + "[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1),
    "an unclosed flow sequence": "a: [1, 2",
    "a tab for indentation": "a:\n\tb: 1",
    "an undefined alias": "a: *nothing",
    "a python tag": "a: !!python/object/apply:os.system ['true']",
}


@pytest.mark.parametrize("what", sorted(HOSTILE))
def test_every_hostile_document_is_one_line_naming_where(what):
    for error in (InputError, ConfigError):
        with pytest.raises(error) as caught:
            load_yaml(HOSTILE[what], "site.yaml", error)
        message = str(caught.value)
        assert message.startswith("site.yaml: ") and "\n" not in message, (what, message)


def test_a_document_within_the_depth_loads():
    assert load_yaml("a: " + "[" * MAX_DEPTH + "]" * MAX_DEPTH, "x")["a"] is not None
    assert load_yaml("/**:\n  ros__parameters:\n    a: {b: [1, 2.5]}\n", "x") == {"/**": {"ros__parameters": {
        "a": {"b": [1, 2.5]}}}}


def test_the_issue_repro_is_one_line_through_the_command_line(tmp_path):
    """batch --site with a site whose radius is 20,000 nested lists (the campaign's repro)."""
    text = SITE_FILE.read_text().replace("curve_radius_m: 250.0", "curve_radius_m: " + "[" * 20000 + "]" * 20000, 1)
    site = tmp_path / "s.yaml"
    site.write_text(text)
    csv = tmp_path / "p.csv"
    csv.write_text("time_utc,train_id,vehicle_class,vehicle_count,speed_kmh,aoa_mrad,friction\n")
    for args in (("batch", str(csv), "--site", str(site), "--no-report"), ("site", str(tmp_path / "n.yaml"),
                                                                            "--site", str(site))):
        r = run_cmd("rail-monitor", *args)
        assert r.returncode != 0 and "Traceback" not in r.stderr, r.stderr[-2000:]
        lines = [line for line in r.stderr.splitlines() if line.strip()]
        assert len(lines) == 1 and str(site) in lines[0] and "nested too deeply" in lines[0], r.stderr


def test_brackets_in_quotes_and_comments_do_not_count_toward_the_depth():
    """The pre-scan of flow nesting (before the parser) skips quoted text and comments: a document
    with 150 '[' inside a double-quoted string (one escaped quote among them), a single-quoted string
    and a comment loads."""
    deep = "[" * 150
    text = f'a: "x\\" {deep}"\nb: \'{deep}\'\n# {deep}\nc: [1, [2]]\n'
    doc = load_yaml(text, "x")
    assert doc["a"] == f'x" {deep}' and doc["b"] == deep and doc["c"] == [1, [2]]
