"""Checkpoints: round trip, refusals, fallback to the previous good file
(rail_monitor.engine.checkpoint)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from corrugation.conftest import _estimator, _passes

from rail_monitor.core.errors import ConfigError
from rail_monitor.corrugation import surveys
from rail_monitor.engine import checkpoint
from rail_monitor.engine.checkpoint import CorruptCheckpoint


def test_checkpoint_round_trip_and_refusals(site_, tables, tmp_path):
    est = _estimator(site_, tables)
    passes = _passes(site_, np.linspace(15, 21, 200))
    est.advance(passes.take(slice(0, 150)))
    surveys.apply_survey(est, est.bands, est.amplitude * 1.1)
    path = tmp_path / "state" / "corrugation.npz"
    checkpoint.save(est, path)
    assert [p.name for p in path.parent.iterdir()] == ["corrugation.npz"]   # no temporary left behind
    again = _estimator(site_, tables)
    checkpoint.load(again, path)
    np.testing.assert_array_equal(again.log_components, est.log_components)
    np.testing.assert_array_equal(again.k_b, est.k_b)
    est.advance(passes.take(slice(150, 160)))
    checkpoint.save(est, path)
    again = _estimator(site_, tables)
    checkpoint.load(again, path)
    for name in ("growth_by_state", "level_cov", "level_kb_cov"):
        np.testing.assert_array_equal(getattr(again, name), getattr(est, name))
    np.testing.assert_array_equal(again.calibration.cov, est.calibration.cov)
    np.testing.assert_allclose(again.calibration.mean, est.calibration.mean, atol=1e-15)
    assert again.calibration.fits == est.calibration.fits
    assert again.total_pass_count == 160
    # Resumed: the passes already counted are recognised, the rest count.
    assert again.advance(passes).sum() == 40
    est.advance(passes)
    np.testing.assert_allclose(again.log_components, est.log_components, rtol=0, atol=1e-12)
    (tmp_path / "bad.npz").write_bytes(b"not a checkpoint")
    with pytest.raises(ConfigError, match="not a readable corrugation checkpoint"):
        checkpoint.load(again, tmp_path / "bad.npz")
    other = _estimator(site_, None, longest_wavelength_m=0.5)
    with pytest.raises(ConfigError, match="bands differ"):
        checkpoint.load(other, path)


def test_an_unreadable_checkpoint_falls_back_to_the_previous_one(site_, tables, tmp_path, tally):
    """Issue 8: a corrupt or truncated newest checkpoint is detected (zip CRCs, missing arrays) and
    the previous good one is resumed; with neither readable the estimator refuses, never zero."""
    est = _estimator(site_, tables)
    passes = _passes(site_, np.linspace(15, 21, 300))
    path = tmp_path / "corrugation.npz"
    est.advance(passes.take(slice(0, 100)))
    checkpoint.save(est, path)
    at_100 = est.log_components.copy()
    est.advance(passes.take(slice(100, 200)))
    checkpoint.save(est, path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["corrugation.npz", "corrugation.npz.prev"]
    newest = path.read_bytes()
    faults = {"truncated": newest[: len(newest) // 2], "zero-length": b"",
              "flipped byte": newest[:200] + bytes([newest[200] ^ 0xFF]) + newest[201:],
              "not a zip": b"PK\x03\x04" + b"\x00" * 64}
    for what, data in faults.items():
        path.write_bytes(data)
        again = _estimator(site_, tables)
        used, skipped = checkpoint.resume(again, path)
        assert used == tmp_path / "corrugation.npz.prev", what
        assert len(skipped) == 1 and str(path) in skipped[0] and "\n" not in skipped[0], what
        np.testing.assert_array_equal(again.log_components, at_100)
        assert again.total_pass_count == 100
        # replaying the history counts only what the fallback had not seen
        assert again.advance(passes.take(slice(0, 200))).sum() == 100, what
        np.testing.assert_array_equal(again.log_components, est.log_components)
    # a crash between save()'s two renames leaves only the previous file
    path.unlink()
    assert checkpoint.resume(_estimator(site_, tables), path)[0] == tmp_path / "corrugation.npz.prev"
    # both unreadable: refuse (one line), do not start from zero
    path.write_bytes(b"")
    (tmp_path / "corrugation.npz.prev").write_bytes(newest[:300])
    with pytest.raises(CorruptCheckpoint, match="no readable previous checkpoint") as err:
        checkpoint.resume(_estimator(site_, tables), path)
    assert "\n" not in str(err.value)
    assert checkpoint.resume(_estimator(site_, tables), tmp_path / "none.npz") == (None, [])
    tally("checkpoint", f"{len(faults)} corrupt newest checkpoints, both corrupt, crash between renames",
          "previous good state resumed; refusal when neither is readable", 0)


def _crafted(est, path, change: dict) -> None:
    """A checkpoint of est written normally, then rewritten as a valid .npz with some members changed."""
    checkpoint.save(est, path)
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files}
    data.update(change)
    with open(path, "wb") as fh:
        np.savez(fh, **data)


@pytest.mark.parametrize("change", [
    lambda est: {"meta": np.array("[1, 2, 3]")},                              # a meta record that is no mapping
    lambda est: {"k_b": np.zeros(3)},                                         # K_b of 3 friction states
    lambda est: {"log_components": np.full(est.log_components.shape, np.nan)},  # not finite
    lambda est: {"recent_speed": np.zeros(2)},                                # kept-pass columns of other lengths
    lambda est: {"recent_class_idx": np.full(len(est.kept), 7)},             # a class the site does not have
    lambda est: {"recent_stamp_ns": np.array(["x"] * len(est.kept))},         # strings for stamps
    lambda est: {"grinding_amplitude": np.zeros(len(est.bands))},             # post-grinding amplitudes of zero
    lambda est: {"recent_regime": np.full(len(est.kept), 2)},                # a contact regime that does not exist
    lambda est: {"recent_load": np.full(len(est.kept), np.inf)},             # a load that is not finite
])
def test_a_crafted_checkpoint_is_refused_and_leaves_the_state_as_it_was(site_, tables, tmp_path, change):
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 150))
    path = tmp_path / "c.npz"
    _crafted(est, path, change(est))
    fresh = _estimator(site_, tables)
    before = fresh.log_components.copy()
    with pytest.raises(CorruptCheckpoint) as err:
        checkpoint.load(fresh, path)
    assert "\n" not in str(err.value) and str(path) in str(err.value)
    np.testing.assert_array_equal(fresh.log_components, before)
    assert fresh.total_pass_count == 0 and len(fresh.kept) == 0


def test_a_version_2_checkpoint_resumes_with_its_passes_in_partial_slip(site_, tables, tmp_path):
    # Version 2 (rail_monitor 0.2) kept no contact regime: every pass was counted in partial slip,
    # and the kept passes are read so, at their class's nominal load, with the state as it was.
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 150))
    path = tmp_path / "v2.npz"
    checkpoint.save(est, path)
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files if k not in ("recent_regime", "recent_load", "recent_creepage")}
    meta = json.loads(str(data["meta"]))
    data["meta"] = np.array(json.dumps({**meta, "version": 2}))
    with open(path, "wb") as fh:
        np.savez(fh, **data)
    again = _estimator(site_, tables)
    checkpoint.load(again, path)
    np.testing.assert_array_equal(again.log_components, est.log_components)
    assert not again.kept.regime.any() and np.all(again.kept.load == site_.vehicle("emu").wheel_load_n)
    np.testing.assert_allclose(again.recent_growth(), est.recent_growth(), rtol=1e-12)


def test_a_version_5_checkpoint_resumes_with_its_levels_uncorrelated_and_no_season(site_, tables, tmp_path):
    # Version 5 (0.30.0) kept each band's level variance alone and the daily passes of all friction
    # states together: read as the levels' diagonal, uncorrelated with K_b, and as no season (the
    # forecast follows the recent window until a year has passed), the rest as it was.
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 150))
    surveys.apply_survey(est, est.bands, est.amplitude * 1.1)
    est.advance(_passes(site_, [19.0] * 150, start_s=100_000, prefix="U"))
    surveys.apply_survey(est, est.bands, est.amplitude * 1.1, est.newest_ns)
    assert np.any(est.level_kb_cov != 0) and np.any(est.level_cov != np.diag(np.diag(est.level_cov)))
    path = tmp_path / "v5.npz"
    checkpoint.save(est, path)
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files if k not in ("level_cov", "level_kb_cov")}
    data["level_var"] = np.diag(est.level_cov)
    data["season_passes"] = data["season_passes"].sum(axis=1)
    data["meta"] = np.array(json.dumps({**json.loads(str(data["meta"])), "version": 5}))
    with open(path, "wb") as fh:
        np.savez(fh, **data)
    again = _estimator(site_, tables)
    checkpoint.load(again, path)
    np.testing.assert_array_equal(again.level_cov, np.diag(np.diag(est.level_cov)))
    assert not again.level_kb_cov.any() and len(again.season.passes) == 0
    np.testing.assert_array_equal(again.calibration.cov, est.calibration.cov)
    np.testing.assert_array_equal(again.log_components, est.log_components)


@pytest.mark.parametrize("name, bad", [
    ("level_cov", lambda a: np.where(np.eye(len(a), dtype=bool), np.nan, a)),           # not finite
    ("level_cov", lambda a: a - 2.0 * np.diag(np.diag(a))),                               # negative variances
    ("level_kb_cov", lambda a: a[:-1]),                                                    # wrong shape
    ("level_kb_cov", lambda a: a + 1.0),                                                   # not a covariance
    ("season_passes", lambda a: a.sum(axis=1)),                                            # one count a day
])
def test_a_checkpoint_whose_covariances_or_season_are_not_a_state_is_refused(site_, tables, tmp_path, name, bad):
    # One line, CorruptCheckpoint, and the estimator left as it was.
    est = _estimator(site_, tables)
    est.advance(_passes(site_, [19.0] * 150))
    surveys.apply_survey(est, est.bands, est.amplitude * 1.1)
    path = tmp_path / "c.npz"
    checkpoint.save(est, path)
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files}
    data[name] = bad(data[name])
    with open(path, "wb") as fh:
        np.savez(fh, **data)
    fresh = _estimator(site_, tables)
    before = (fresh.level_cov.copy(), fresh.level_kb_cov.copy(), fresh.log_components.copy())
    with pytest.raises(CorruptCheckpoint) as info:
        checkpoint.load(fresh, path)
    assert "\n" not in str(info.value)
    for a, b in zip(before, (fresh.level_cov, fresh.level_kb_cov, fresh.log_components), strict=True):
        np.testing.assert_array_equal(a, b)


def test_the_writer_writes_the_newest_state_off_the_callers_thread(site_, tables, tmp_path):
    """CheckpointWriter: each write on its own thread, the newest submitted state the one on disk
    after flush (one still waiting is replaced, and counted), a failure counted and reported
    without stopping the thread, nothing written after close; a snapshot is the state when it was
    taken, whatever the state does after, and encodes to the bytes save() writes."""
    import threading

    est = _estimator(site_, tables)
    passes = _passes(site_, np.linspace(15, 21, 60))
    path = tmp_path / "corrugation.npz"
    threads, failures = [], []
    writer = checkpoint.CheckpointWriter(path, on_written=lambda data: threads.append(threading.current_thread()),
                                         on_error=failures.append)
    for k in range(0, 60, 10):
        est.advance(passes.take(slice(k, k + 10)))
        writer.submit(checkpoint.snapshot(est))
    assert writer.flush(30.0)
    assert writer.written + writer.coalesced == 6 and writer.written >= 1 and not failures
    assert threads and all(t is not threading.current_thread() for t in threads)
    again = _estimator(site_, tables)
    checkpoint.load(again, path)
    assert again.total_pass_count == 60
    np.testing.assert_array_equal(again.log_components, est.log_components)
    np.testing.assert_array_equal(again.kept.stamp_ns, est.kept.stamp_ns)

    early = checkpoint.snapshot(est)
    est.advance(_passes(site_, np.linspace(15, 21, 5), start_s=1e6))
    checkpoint.write_atomically(checkpoint.encode(early), tmp_path / "early.npz")
    checkpoint.save(again, tmp_path / "again.npz")
    assert (tmp_path / "early.npz").read_bytes() == (tmp_path / "again.npz").read_bytes()
    assert est.total_pass_count == 65

    (tmp_path / "blocked").write_text("a file where the folder should be")
    bad = checkpoint.CheckpointWriter(tmp_path / "blocked" / "corrugation.npz", on_error=failures.append)
    bad.submit(checkpoint.snapshot(est))
    assert bad.flush(30.0) and bad.failed == 1 and bad.written == 0 and isinstance(failures[0], OSError)
    bad.submit(checkpoint.snapshot(est))  # the thread goes on after a failure
    assert bad.close(30.0) and bad.failed == 2
    assert writer.close(30.0)
    with pytest.raises(RuntimeError, match="closed"):
        writer.submit(b"")
