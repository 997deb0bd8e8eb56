"""rail-monitor plan (issue 57): a manifest of sites read as histories or checkpoints into their
grinding outlooks, the programme printed and written, and bad input refused in one line."""

from __future__ import annotations

import csv
import re

import numpy as np
import pytest

from rail_monitor.batch.sites import SiteJob, outlook_site, read_manifest
from rail_monitor.cli import main
from rail_monitor.core.errors import ConfigError

from conftest import write_two_sites


@pytest.fixture(scope="module")
def network(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("network")
    write_two_sites(tmp, 3.0)
    _checkpoint(tmp / "curve_400.yaml", tmp / "b.csv", tmp / "b.npz")
    (tmp / "sites.yaml").write_text("sites:\n  - site: curve_250.yaml\n    history: a.csv\n"
                                    "  - site: curve_400.yaml\n    checkpoint: b.npz\n")
    return tmp


def _checkpoint(site, history, path):
    """The corrugation checkpoint a live site engine would hold after the history."""
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.core.passes import accepted_passes
    from rail_monitor.corrugation.estimator import CorrugationEstimator
    from rail_monitor.engine import checkpoint
    from rail_monitor.engine.site_config import SiteConfig
    from rail_monitor.site_file import load_parameter_file

    cfg = SiteConfig.from_values(load_parameter_file(site))
    est = CorrugationEstimator(cfg.site, cfg.corrugation)
    passes = read_passes(history)
    est.advance(accepted_passes(passes, cfg.site))
    checkpoint.save(est, path)


def test_a_checkpoint_gives_the_outlook_its_history_gives(network):
    """A live site's checkpoint (engine.checkpoint, written after its history) and the history itself give
    the same due dates, cycle and costs, to the bit."""
    site = network / "curve_400.yaml"
    a = outlook_site(SiteJob(site, network / "b.csv", None))
    b = outlook_site(SiteJob(site, None, None, network / "b.npz"))
    assert a.newest_ns == b.newest_ns and a.visit_cost == b.visit_cost
    np.testing.assert_array_equal(a.due_days, b.due_days)
    np.testing.assert_array_equal(a.cycle_days, b.cycle_days)
    assert np.all(np.isfinite(a.due_days)) and a.due_days[0] < a.due_days[2]


def test_plan_prints_and_writes_the_programme(network, capsys):
    """Both sites ranked, a programme of three years within one visit a month, the two baselines
    priced beside it; the CSV holds a row per visit, the workbook the same rows and the sites, and the
    timeline is a PNG."""
    out = network / "programme.csv"
    assert main(["plan", str(network / "sites.yaml"), "--workers", "1", "--years", "3", "--capacity", "1",
                 "--csv", str(out), "--xlsx", str(network / "programme.xlsx"), "--plot",
                 str(network / "timeline.png"), "--report", str(network / "report")]) == 0
    printed = capsys.readouterr().out
    assert "2 sites, 36 months" in printed and "curve_250" in printed and "curve_400" in printed
    assert re.search(r"plan: programme: [0-9]+ visits, expected cost [0-9]+", printed)
    assert re.search(r"plan: fixed [0-9]+-month cycle: [0-9]+ visits", printed)
    assert "plan: when due (forecast median): " in printed
    rows = list(csv.DictReader(out.open()))
    months = [r["month_start"] for r in rows]
    assert rows and len(set(months)) == len(months)          # capacity 1: never two visits in a month
    assert {r["site_id"] for r in rows} <= {"curve_250", "curve_400"}
    import pandas as pd

    book = pd.read_excel(network / "programme.xlsx", sheet_name=None)
    assert set(book) == {"programme", "sites"} and len(book["programme"]) == len(rows)
    assert (network / "timeline.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = (network / "report" / "index.html").read_text()
    cost = re.search(r"plan: programme: ([0-9]+) visits, expected cost ([0-9]+)", printed)
    fixed = re.search(r"plan: fixed ([0-9]+)-month cycle: [0-9]+ visits, expected cost ([0-9]+)", printed)
    assert f"{cost[1]} grinding visits, expected cost {int(cost[2]):,}" in page     # the printed numbers
    saving = re.search(rf"Against fixed {fixed[1]}-month cycle: .*? the programme (saves|costs) ([0-9,]+)", page)
    saved = int(saving[2].replace(",", "")) * (1 if saving[1] == "saves" else -1)
    assert abs(saved - (int(fixed[2]) - int(cost[2]))) <= 1                          # each rounded
    assert "Risk left:" in page and "What to grind when" in page and page.count("<tr>") >= 1 + len(rows)
    assert (network / "report" / "programme.pdf").read_bytes()[:5] == b"%PDF-"


def test_bad_plan_input_is_one_line(network, capsys):
    """A manifest entry with a history and a checkpoint, a checkpoint given to batch, a risk out of range."""
    m = network / "bad.yaml"
    m.write_text("sites:\n  - site: curve_250.yaml\n    history: a.csv\n    checkpoint: b.npz\n")
    with pytest.raises(ConfigError, match="history or checkpoint"):
        read_manifest(m, checkpoints=True)
    with pytest.raises(ConfigError, match="expected the keys"):
        read_manifest(network / "sites.yaml")                # a checkpoint is plan's, not batch's
    assert main(["plan", str(network / "sites.yaml"), "--risk", "1.5"]) == 2
    err = capsys.readouterr().err
    assert "--risk in (0, 1)" in err and len(err.strip().splitlines()) == 1


def test_plan_chooses_an_option_where_a_site_offers_it(network, capsys):
    """curve_250 offering speed control and a friction modifier at 1 a year (against 500 a visit):
    the ranking lists each option with its cycle and effects, the programme runs the modifier there
    (it lengthens the cycle at almost no cost), and the CSV says so on each of its visits."""
    from rail_monitor.cli.site import edited_site_text

    text, _ = edited_site_text((network / "curve_250.yaml").read_text(), [
        "economics.options=[grind, speed_control, friction_modifier]", "economics.applicator_cost_per_year=1"])
    (network / "curve_250_options.yaml").write_text(text)
    (network / "options.yaml").write_text("sites:\n  - site: curve_250_options.yaml\n    history: a.csv\n")
    out = network / "options.csv"
    assert main(["plan", str(network / "options.yaml"), "--workers", "1", "--csv", str(out)]) == 0
    printed = capsys.readouterr().out
    for name in ("grind", "speed_control", "friction_modifier"):
        assert re.search(rf"option {name}: cycle [0-9]+-[0-9]+-[0-9]+ d", printed)
    assert "squealing passes" in printed and "running time" in printed
    assert "(friction_modifier from the first visit)" in printed
    rows = list(csv.DictReader(out.open()))
    assert rows and {r["option"] for r in rows} == {"friction_modifier"}


def test_replan_re_plans_on_each_outlook_of_the_histories(tmp_path, capsys):
    """plan --replan on a simulated network of three curves surveyed every five days: one row per
    outlook the sites' engines made (each survey applied while passes were taken), in stamp order,
    the last the programme of every site's newest outlook (economics.replan.replay, the planner node's
    re-plans); each outlook is the one its site's batch run records."""
    from rail_monitor.bagio.reader import read_messages
    from rail_monitor.batch.sites import outlook_history
    from rail_monitor.economics.replan import Replanner, replay
    from rail_monitor.messages.economics_fields import outlook_from_msg

    net = tmp_path / "net"
    assert main(["simulate", "--network", "3", "--days", "30", "--surveys-every-days", "5", "--out", str(net)]) == 0
    out = tmp_path / "replans.csv"
    assert main(["plan", str(net / "sites.yaml"), "--workers", "1", "--years", "2", "--replan", str(out)]) == 0
    assert "re-plans, one per site outlook" in capsys.readouterr().out
    rows = list(csv.DictReader(out.open()))
    jobs = read_manifest(net / "sites.yaml", checkpoints=True)
    histories = [outlook_history(j)[1] for j in jobs]
    assert len(rows) == sum(map(len, histories)) and all(len(h) >= 4 for h in histories)
    assert [r["made"] for r in rows] == sorted(r["made"] for r in rows)
    replans = replay([x for h in histories for x in h], Replanner(2.0))
    assert float(rows[-1]["expected_cost"]) == pytest.approx(replans[-1].programme.expected_cost.sum(), rel=1e-9)
    assert int(rows[-1]["sites_planned"]) == 3 and rows[0]["sites_planned"] == "1"
    # the batch run of a site records the same outlooks on grinding/outlook
    job = jobs[0]
    assert main(["batch", str(job.history), "--site", str(job.site), "--output", str(tmp_path / "bag"),
                 "--no-report"]) == 0
    recorded = read_messages(tmp_path / "bag", ["rail_msgs/msg/GrindingOutlook"])["rail_msgs/msg/GrindingOutlook"]
    assert len(recorded) == len(histories[0])
    for msg, (stamp, o) in zip(recorded, histories[0], strict=True):
        got_stamp, got = outlook_from_msg(msg)
        assert got_stamp == stamp and got.newest_ns == o.newest_ns
        np.testing.assert_array_equal(got.due_days, o.due_days)
