"""Batch outputs recorded chunk by chunk (rail_monitor.batch.bag and rail-monitor batch on a
bag): the bag of a streamed run holds, topic by topic, the very bytes of the one-call run's bag."""

from __future__ import annotations

from collections import defaultdict

import pytest
from mcap.reader import make_reader

from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.passes_bag import pass_cdr, write_passes_bag
from rail_monitor.bagio.reader import iter_bag_passes, read_bag_passes
from rail_monitor.batch.bag import run_to_bag, write_bag
from rail_monitor.batch.run import run_models
from rail_monitor.cli import main
from rail_monitor.codec.typestore import TRAIN_PASS
from rail_monitor.messages.topics import STREAM


def _messages(folder):
    """Per topic, (log time, CDR bytes) in file order, over the bag's files."""
    out = defaultdict(list)
    for f in sorted(folder.glob("*.mcap")):
        with open(f, "rb") as fh:
            for _, channel, message in make_reader(fh).iter_messages(log_time_order=True):
                out[channel.topic].append((message.log_time, bytes(message.data)))
    return dict(out)


@pytest.fixture(scope="module")
def history(tmp_path_factory, sample_passes):
    passes = sample_passes.sorted().take(slice(0, 3000))
    return passes, write_passes_bag(passes, tmp_path_factory.mktemp("h") / "history", "curve_250")


def test_a_bag_recorded_chunk_by_chunk_holds_the_one_call_bag_message_for_message(tmp_path, history,
                                                                                    site_values):
    passes, bag = history
    one = write_bag(run_models(read_bag_passes(bag), site_values), tmp_path / "one", "curve_250")
    rec = run_to_bag(iter_bag_passes(bag, chunk=437), site_values, tmp_path / "streamed", "curve_250")
    assert rec.passes == len(passes)
    a, b = _messages(one), _messages(tmp_path / "streamed")
    assert set(a) == set(b) and len(a["/curve_250/speed_advisory"]) == 1
    assert len(a["/curve_250/alerts"]) == rec.alert_events >= 2
    for topic, msgs in a.items():
        assert b[topic] == msgs, topic


def test_batch_streams_a_bag_and_reads_one_out_of_time_order_whole(tmp_path, history, site_values, capsys):
    passes, bag = history
    assert main(["batch", str(bag), "--output", str(tmp_path / "streamed"), "--no-report", "--chunk", "500"]) == 0
    assert "reading it whole" not in capsys.readouterr().out
    # The same passes logged in another order (a recorder's log time is when a pass arrived).
    shuffled = tmp_path / "shuffled"
    order = list(range(len(passes)))
    order[100:1100] = order[1099:99:-1]
    with McapBagWriter(shuffled) as w:
        w.add_topic("/train_pass", TRAIN_PASS, [STREAM.as_metadata()])
        cdr = pass_cdr(passes, "curve_250")
        for log, i in enumerate(order):
            w.write("/train_pass", cdr[i], 1_000_000_000 + log)
    assert main(["batch", str(shuffled), "--output", str(tmp_path / "sorted"), "--no-report", "--chunk", "500"]) == 0
    assert "passes out of time order" in capsys.readouterr().out
    assert _messages(tmp_path / "sorted") == _messages(tmp_path / "streamed")


def test_a_bag_found_bad_while_streaming_leaves_no_output(tmp_path, history, capsys):
    _, bag = history
    meta = (bag / "metadata.yaml").read_text()
    broken = tmp_path / "broken"
    broken.mkdir()
    for f in bag.iterdir():
        (broken / f.name).write_bytes(f.read_bytes())
    (broken / "metadata.yaml").write_text(meta.replace("message_count: 3000", "message_count: 3001"))
    out = tmp_path / "out"
    assert main(["batch", str(broken), "--output", str(out), "--no-report", "--chunk", "500"]) == 2
    assert "3001" in capsys.readouterr().err and not out.exists()


def test_batch_applies_and_records_the_history_s_surveys_streamed_as_in_one_call(tmp_path, history, site_values,
                                                                                 capsys):
    """A history bag with surveys and a grinding (rail-monitor batch reads them from it): the
    streamed run's bag holds the one call's messages, the surveys on roughness_survey among them."""
    import numpy as np

    from rail_monitor.bagio.reader import read_bag_events
    from rail_monitor.corrugation.surveys import KIND_GRINDING, KIND_SURVEY, MaintenanceEvent

    passes, _ = history
    from rail_monitor.core.site import site_from_values
    from rail_monitor.corrugation.config import corrugation_config
    from rail_monitor.corrugation.estimator import CorrugationEstimator

    est = CorrugationEstimator(site_from_values(site_values), corrugation_config(site_values))
    t = passes.stamp_ns
    events = [MaintenanceEvent(int(t[800]) + 1, KIND_SURVEY, est.bands, 1.5 * est.post_grinding),
              MaintenanceEvent(int(t[1700]) + 1, KIND_GRINDING, np.zeros(0), np.zeros(0)),
              MaintenanceEvent(int(t[-1]) + 1, KIND_SURVEY, est.bands[:5], 1.1 * est.post_grinding[:5])]
    bag = write_passes_bag(passes, tmp_path / "with_surveys", "curve_250", events=events)
    assert [(e.stamp_ns, e.kind) for e in read_bag_events(bag)] == [(e.stamp_ns, e.kind) for e in events]
    assert main(["batch", str(bag), "--output", str(tmp_path / "streamed"), "--no-report", "--chunk", "333"]) == 0
    said = capsys.readouterr().out
    assert "3 roughness survey(s) and grinding event(s) read: 3 applied in stamp order, 0 refused" in said
    one = write_bag(run_models(read_bag_passes(bag), site_values, events=events), tmp_path / "one", "curve_250")
    a, b = _messages(one), _messages(tmp_path / "streamed")
    assert len(a["/curve_250/roughness_survey"]) == 3
    assert set(a) == set(b)
    for topic, msgs in a.items():
        assert b[topic] == msgs, topic
    plain = _messages(write_bag(run_models(read_bag_passes(bag), site_values), tmp_path / "plain", "curve_250"))
    assert plain["/curve_250/corrugation/state"][:800] == a["/curve_250/corrugation/state"][:800]
    assert plain["/curve_250/corrugation/state"][801] != a["/curve_250/corrugation/state"][801]


def test_batch_records_the_history_s_applicator_events_and_leaves_out_a_bad_one(tmp_path, history, capsys):
    """A history bag with a friction-modifier applicator's start and stop and one event of no known
    action: rail-monitor batch records the two on friction_applicator (at their stamps, as the
    replayer sends them), says the third was left out and why, and the report compares before and
    after the start."""
    from rail_monitor.bagio.reader import read_applicators
    from rail_monitor.core.friction import ACTION_START, ACTION_STOP, ApplicatorEvent

    passes, _ = history
    t = passes.stamp_ns
    good = [ApplicatorEvent(int(t[1000]) + 1, ACTION_START, "modifier A"), ApplicatorEvent(int(t[2500]) + 1,
                                                                                         ACTION_STOP, "modifier A")]
    bad = ApplicatorEvent(int(t[2000]), 9, "?")
    bag = write_passes_bag(passes, tmp_path / "with_applicator", "curve_250", applicators=[good[0], bad, good[1]])
    assert read_applicators(bag) == (good, {"action 9 is not start (1) or stop (2)": 1})
    out = tmp_path / "out"
    assert main(["batch", str(bag), "--output", str(out), "--chunk", "700"]) == 0
    said = capsys.readouterr().out
    assert "1 friction applicator event(s) of" in said and "left out: action 9 is not start (1) or stop (2)" in said
    recorded = _messages(out)["/curve_250/friction_applicator"]
    assert [stamp for stamp, _ in recorded] == [e.stamp_ns for e in good]
    assert read_applicators(out) == (good, {})
    assert "squeal before and after the applicator" in (tmp_path / "out_report" / "index.html").read_text()
