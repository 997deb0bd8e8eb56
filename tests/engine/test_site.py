"""Batch mode without ROS (rail_monitor.batch.run): it imports and records a bag with rclpy and the
generated messages unavailable, and that bag decodes to what the rclpy path gives."""

from __future__ import annotations

import subprocess
import sys
import textwrap

from conftest import SITE_FILE, TOP

# Run in a fresh interpreter in which importing rclpy or the generated rail_msgs / diagnostic_msgs /
# builtin_interfaces Python packages fails, as on a machine without them.
_NO_ROS = textwrap.dedent("""
    import sys
    for name in ("rclpy", "rail_msgs", "builtin_interfaces", "std_msgs", "diagnostic_msgs", "rosgraph_msgs"):
        sys.modules[name] = None  # import raises ImportError
    import rail_monitor.batch.run as batch
    import rail_monitor.batch.bag as batch_bag
    import rail_monitor.report.summary
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.site_file import load_parameter_file
    values = load_parameter_file(sys.argv[1])
    result = batch.run_models(read_passes(sys.argv[2]), values)
    batch_bag.write_bag(result, sys.argv[3], "curve_250")
    assert not any(m == "rclpy" or m.startswith(("rclpy.", "rail_msgs.")) for m in sys.modules if sys.modules[m])
    print(len(result.passes), len(result.trajectory))
""")


def test_batch_imports_and_records_without_rclpy_or_generated_messages(tmp_path):
    out = tmp_path / "bag"
    r = subprocess.run([sys.executable, "-c", _NO_ROS, str(SITE_FILE), str(TOP / "bags" / "example_passes.csv"),
                        str(out)], capture_output=True, text=True, timeout=120, cwd=TOP)
    assert r.returncode == 0, r.stderr[-2000:]
    passes, states = map(int, r.stdout.split())
    assert passes == 194 and states == 194
    assert (out / "metadata.yaml").exists()


def test_a_bag_written_without_rclpy_decodes_with_rclpy_to_the_same_messages(tmp_path, site_values):
    """Every message batch mode serialises (rosbags' CDR) decodes with rclpy's own deserialiser to the
    message the live graph would build from the same fields."""
    from mcap.reader import make_reader
    from rclpy.serialization import deserialize_message

    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.batch.bag import write_bag
    from rail_monitor.batch.run import run_models
    from rail_monitor.nodes.convert import TOPICS

    # a limit the history's loudest passes exceed, so that alerts (and their standing set) are written too
    values = {**site_values, "alerts.noise_limit_dba": 80.0}
    write_bag(run_models(read_passes(TOP / "bags" / "example_passes.csv"), values), tmp_path / "b", "site")
    seen = set()
    with open(next((tmp_path / "b").glob("*.mcap")), "rb") as fh:
        for _, channel, message in make_reader(fh).iter_messages():
            name = channel.topic.removeprefix("/site/")
            msg = deserialize_message(message.data, TOPICS[name][0])
            assert msg.header.stamp.sec > 0 and msg.header.frame_id == "curve_250"
            seen.add(name)
    assert seen == set(TOPICS)


# -- a history in chunks -------------------------------------------------------------------------
def _hostile_history(passes):
    """The sample's first 4,000 passes with what makes chunking hard: duplicates (a pass sent twice,
    adjacent once sorted), passes sharing a stamp, invalid and unknown-class passes, unset and
    pre-1970 stamps, a far-future stamp and an unrepresentable one."""
    import numpy as np

    from rail_monitor.core.passes import PassTable

    rng = np.random.default_rng(7)
    base = passes.sorted().take(slice(0, 4000))
    dup = base.take(rng.choice(len(base), 60, replace=False))
    same = base.take(rng.choice(len(base), 40, replace=False))
    same.train_id = np.array([f"{t}-b" for t in same.train_id], dtype=object)
    bad = base.take(rng.choice(len(base), 40, replace=False))
    bad.speed_mps[:20] = np.nan
    bad.vehicle_class[20:] = "tram"
    odd = base.take(np.arange(5))
    odd.stamp_ns = np.array([0, -5_000_000_000, base.stamp_ns[-1] + 400 * 86_400 * 10**9, 2**62,
                             base.stamp_ns[-1]], np.int64)
    return PassTable.concat([base, dup, same, bad, odd]).sorted()


def _chunked(passes, values, cuts, events=()):
    from rail_monitor.engine.site import SiteEngine

    run = SiteEngine(values, events=events)
    parts = [run.feed(passes.take(slice(a, b))) for a, b in zip([0, *cuts], [*cuts, len(passes)], strict=True)]
    held, advice = run.finish()
    return run, parts, held, advice


def test_any_chunking_of_a_history_gives_the_one_call_outputs_alerts_included(site_values, sample_passes):
    """SiteEngine carries the state, the alert windows and standing alerts, the stream's references and
    the states a later pass is predicted on: random chunk boundaries (an empty chunk, a boundary
    inside a run of equal stamps) give the one call's outputs bit for bit (exact equality)."""
    import numpy as np

    from rail_monitor.batch.run import run_models
    from rail_monitor.engine.result import SiteOutputs

    history = _hostile_history(sample_passes)
    whole = run_models(history, site_values)
    assert len(whole.alerts) >= 4 and (whole.reasons != "").sum() >= 42 and len(whole.left_out) == 2
    assert len(whole.trajectory) <= len(whole.accepted) - 60  # the duplicates are not counted
    rng = np.random.default_rng(11)
    stamps = history.stamp_ns
    tie = int(np.flatnonzero(stamps[1:] == stamps[:-1])[5]) + 1  # between two passes of one stamp
    for cuts in (sorted({*rng.choice(len(history), 9, replace=False).tolist(), tie, tie}),
                 [tie, 1500, 1500, 3000], [1]):
        run, parts, held, advice = _chunked(history, site_values, cuts)
        got = SiteOutputs.merged(parts, held, advice)
        _assert_same_result(got, whole)
        assert got.left_out == whole.left_out == run.left_out
        assert advice.lines() == whole.advice.lines()


def _assert_same_result(got, whole) -> None:
    """Every output of two batch results is bit for bit the same."""
    import numpy as np

    assert got.passes.equals(whole.passes) and got.accepted.equals(whole.accepted)
    np.testing.assert_array_equal(got.reasons, whole.reasons)
    for k, col in whole.squeal.items():
        np.testing.assert_array_equal(got.squeal[k], col, err_msg=k)
    a, b = whole.trajectory, got.trajectory
    for name in ("index", "stamp_ns", "train_id", "amplitude", "pass_count", "axle_pass_count",
                 "total_pass_count"):
        np.testing.assert_array_equal(getattr(b, name), getattr(a, name), err_msg=name)
    for name in ("growth_per_axle_pass", "worst_band", "passes_to_threshold", "days_to_threshold",
                 "passes_per_day", "grinding_due", "grinding_due_ns"):
        np.testing.assert_array_equal(getattr(b.forecast, name), getattr(a.forecast, name), err_msg=name)
    for k in range(len(a)):  # the constants in force at each pass (K_b, last grinding, ...)
        sa, sb = a.constants_at(k), b.constants_at(k)
        assert (sa.last_grinding_ns, sa.calibration_surveys) == (sb.last_grinding_ns, sb.calibration_surveys), k
        np.testing.assert_array_equal(sa.k_b, sb.k_b)
        np.testing.assert_array_equal(sa.grinding_amplitude, sb.grinding_amplitude)
    for model, out in whole.noise.items():
        for k, col in out.per_pass().items():
            np.testing.assert_array_equal(got.noise[model].per_pass()[k], col, err_msg=f"{model} {k}")
    assert got.alerts == whole.alerts and got.standing == whole.standing


def test_surveys_and_grinding_apply_before_the_first_later_pass_in_any_chunking(site_values, sample_passes):
    """A history's surveys and grinding events (one at a stamp two passes share, one refused as not
    newer, one matching no band, one after the last accepted pass): applied before the first pass stamped
    later, they give the state of an estimator advanced and surveyed by hand in that order, each one
    applied while passes are taken makes the grinding outlook of the state it leaves, and random chunk
    boundaries give the one call's outputs bit for bit."""
    import numpy as np

    from rail_monitor.batch.run import run_models
    from rail_monitor.core.passes import rejection_reasons, with_class_defaults
    from rail_monitor.core.site import site_from_values
    from rail_monitor.corrugation.config import corrugation_config
    from rail_monitor.corrugation.estimator import CorrugationEstimator
    from rail_monitor.corrugation.surveys import KIND_GRINDING, KIND_SURVEY, MaintenanceEvent, apply_event
    from rail_monitor.economics.config import economics_config
    from rail_monitor.economics.outlook import site_outlook
    from rail_monitor.engine.result import SiteOutputs

    history = _hostile_history(sample_passes)
    est = CorrugationEstimator(site_from_values(site_values), corrugation_config(site_values))
    bands, post = est.bands, est.post_grinding
    stamps = history.stamp_ns[history.stamp_ns > 0]
    tie = int(stamps[np.flatnonzero(stamps[1:] == stamps[:-1])[3]])
    at = [int(stamps[len(stamps) * k // 6]) + 1 for k in range(1, 5)]
    events = [MaintenanceEvent(at[0], KIND_SURVEY, bands, 1.5 * post),
              MaintenanceEvent(at[0], KIND_SURVEY, bands, 1.6 * post),            # not newer: refused
              MaintenanceEvent(at[1], KIND_GRINDING, bands[:4], 0.7 * post[:4]),
              MaintenanceEvent(at[2], KIND_SURVEY, np.array([7.0]), np.array([1e-5])),  # no band: refused
              MaintenanceEvent(max(tie, at[2] + 1), KIND_SURVEY, bands[2:9], 1.3 * post[2:9]),
              MaintenanceEvent(at[3], KIND_SURVEY, bands, 1.2 * post),
              # after the last accepted pass (the two far-future ones are rejected)
              MaintenanceEvent(int(np.sort(stamps)[-3]) + 10**9, KIND_SURVEY, bands, 1.1 * post)]
    whole = run_models(history, site_values, events=events)
    assert len(whole.events) == len(events)
    assert whole.estimator.calibration_surveys == 4 and whole.estimator.last_grinding_ns == at[1]

    # by hand: the accepted passes up to each event's stamp, then the event
    sent = history.take(np.isin(history.stamp_ns, whole.passes.stamp_ns))
    accepted = with_class_defaults(whole.passes.take(rejection_reasons(whole.passes, est.site) == ""), est.site)
    refused, made = 0, []
    for e in sorted(events, key=lambda e: e.stamp_ns):
        n = int(np.argmax(accepted.stamp_ns > e.stamp_ns)) if (accepted.stamp_ns > e.stamp_ns).any() else len(accepted)
        est.advance(accepted.take(slice(0, n)))
        accepted = accepted.take(slice(n, None))
        try:
            apply_event(est, e)
        except ValueError:
            refused += 1
            continue
        if (history.stamp_ns > e.stamp_ns).any():  # one after every pass given is applied at the end: no outlook
            made.append((e.stamp_ns, site_outlook(est, economics_config(site_values))))
    assert len(sent) and refused == 2
    # each event applied while passes were taken made the grinding outlook of the state it left
    assert [e.stamp_ns for e, _ in whole.outlooks] == [t for t, _ in made] and len(made) == 5
    for (_, a), (_, b) in zip(whole.outlooks, made, strict=True):
        assert a.newest_ns == b.newest_ns
        np.testing.assert_array_equal(a.due_days, b.due_days)
        np.testing.assert_array_equal(a.cycle_days, b.cycle_days)
    np.testing.assert_array_equal(est.log_components, whole.estimator.log_components)
    np.testing.assert_array_equal(est.k_b, whole.estimator.k_b)

    rng = np.random.default_rng(12)
    for cuts in (sorted(rng.choice(len(history), 11, replace=False).tolist()), [1, 2, 3]):
        run, parts, held, advice = _chunked(history, site_values, cuts, events)
        got = SiteOutputs.merged(parts, held, advice)
        _assert_same_result(got, whole)
        assert sum(run.events_refused.values()) == 2
        assert [e.stamp_ns for e in got.events + run.trailing_events] == [e.stamp_ns for e in whole.events]
        assert [(e.stamp_ns, o.newest_ns) for e, o in got.outlooks] == [(e.stamp_ns, o.newest_ns)
                                                                        for e, o in whole.outlooks]
        for (_, a), (_, b) in zip(got.outlooks, whole.outlooks, strict=True):
            np.testing.assert_array_equal(a.due_days, b.due_days)
        np.testing.assert_array_equal(run.estimator.log_components, whole.estimator.log_components)


def test_a_chunk_older_than_an_earlier_one_is_refused_and_leaves_the_run_as_it_was(site_values, sample_passes):
    import pytest

    from rail_monitor.core.errors import PassOrderError
    from rail_monitor.engine.site import SiteEngine

    history = sample_passes.sorted().take(slice(0, 600))
    run = SiteEngine(site_values)
    run.feed(history.take(slice(300, 600)))
    before = (run.estimator.total_pass_count, run.newest_ns, run.newest_sent_ns, dict(run.alerts.standing))
    with pytest.raises(PassOrderError, match="out of time order"):
        run.feed(history.take(slice(0, 300)))
    assert (run.estimator.total_pass_count, run.newest_ns, run.newest_sent_ns, dict(run.alerts.standing)) == before


def test_one_thread_in_the_callers_thread_gives_the_pools_outputs(site_values, sample_passes):
    """threads=1 (the live node's engine) runs every task in the caller's thread instead of a pool:
    the same outputs, bit for bit, as a pool of two in one call, when fed one pass at a time as the
    live node feeds them (late=True)."""
    from rail_monitor.engine.result import SiteOutputs
    from rail_monitor.engine.site import SiteEngine

    history = sample_passes.sorted().take(slice(0, 400))
    pool = SiteEngine(site_values, threads=2, engine="numpy")
    first = pool.feed(history)
    held, advice = pool.finish()
    whole = SiteOutputs.merged([first], held, advice)
    run = SiteEngine(site_values, threads=1, engine="numpy")
    parts = [run.feed(history.take(slice(i, i + 1)), late=True) for i in range(len(history))]
    held, advice = run.finish()
    _assert_same_result(SiteOutputs.merged(parts, held, advice), whole)
