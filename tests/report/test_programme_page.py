"""The programme's report for a manager (report.programme_page): its headline against the priced
runs, what to grind when against the programme's visits, and the files it writes."""

from __future__ import annotations

import re

from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.economics import baselines
from rail_monitor.economics.programme import Rules, plan
from rail_monitor.report.programme_page import by_month, by_site, headline, write_programme_report
from rail_monitor.simulation.network import network_outlooks


def test_the_report_states_the_programme_and_its_savings(tmp_path):
    """12 sites offering options over three years: every visit appears once under its month, each
    site once (earliest due first) with the option the programme chose; each baseline's line states
    its cost less the programme's (to the unit, as printed); the files are an HTML page, a PDF and a PNG."""
    outlooks = network_outlooks(12, 8, options=True)
    rules = Rules(36, 400 * NS_PER_DAY)
    prog = plan(outlooks, rules)
    runs = baselines.priced(outlooks, rules, prog, baselines.median_cycle_months(outlooks, rules))
    months = by_month(prog, rules)
    assert sum(r["visits"] for r in months) == runs[0].count == sum(len(v) for v in prog.visits)
    assert [r["month"] for r in months] == sorted(r["month"] for r in months)
    sites = by_site(outlooks, prog, rules)
    assert sorted(r["site"] for r in sites) == sorted(prog.sites)
    assert all(r["option"] == prog.option[prog.sites.index(r["site"])] for r in sites)
    assert [r["due P50"] for r in sites] == sorted(r["due P50"] for r in sites)
    lines = headline(prog, rules, runs)
    assert f"{runs[0].count} grinding visits, expected cost {runs[0].cost:,.0f}" in lines[0]
    for run, line in zip(runs[1:], lines[1:3], strict=True):
        m = re.search(r"the programme (saves|costs) ([0-9,]+)", line)
        sign = 1 if m[1] == "saves" else -1
        assert sign * int(m[2].replace(",", "")) == round(run.cost - runs[0].cost)
    files = write_programme_report(tmp_path / "r", outlooks, prog, rules, runs, [])
    assert [f.name for f in files] == ["timeline.png", "programme.pdf", "index.html"]
    assert files[1].read_bytes()[:5] == b"%PDF-" and files[0].read_bytes()[:4] == b"\x89PNG"
    assert "Options offered" in files[2].read_text()
