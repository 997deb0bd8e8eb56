"""Output folders claimed atomically (issue 52: two batch runs into one --output raced; a failing
run deleted the folder the other had made)."""

from __future__ import annotations

import subprocess
from concurrent.futures import ThreadPoolExecutor

import pytest

from rail_monitor.bagio.output_folder import MARKER, claim_output_folder, new_output_folder
from rail_monitor.bagio.reader import read_bag_passes
from rail_monitor.core.errors import RailMonitorError

from conftest import EXAMPLE_CSV


def test_a_folder_is_claimed_once_and_released_only_by_its_claim(tmp_path):
    out = tmp_path / "a" / "out"
    first = claim_output_folder(out)
    assert first.made and first.holds()
    with pytest.raises(RailMonitorError, match="exists and is not empty"):
        claim_output_folder(out)
    (out / "data.mcap").write_bytes(b"x")
    first.empty()
    assert sorted(p.name for p in out.iterdir()) == [MARKER]
    assert new_output_folder(out, first) == out
    first.release()
    assert not out.exists()

    own = tmp_path / "users_own"  # an empty folder the user made: taken, and left as it was found
    own.mkdir()
    taken = claim_output_folder(own)
    assert not taken.made
    (own / "bag.mcap").write_bytes(b"x")
    taken.release()
    assert own.is_dir() and not any(own.iterdir())

    other = claim_output_folder(tmp_path / "b")  # a claim that is no longer the folder's deletes nothing
    (tmp_path / "b" / MARKER).write_text("claim someone-else\n")
    other.release()
    assert (tmp_path / "b").is_dir()


def test_many_claims_at_once_give_one_winner(tmp_path):
    out = tmp_path / "race"

    def attempt(_):
        try:
            return claim_output_folder(out)
        except RailMonitorError:
            return None

    with ThreadPoolExecutor(8) as pool:
        won = [c for c in pool.map(attempt, range(32)) if c is not None]
    assert len(won) == 1


def test_two_batch_runs_into_one_output_never_share_it(tmp_path):
    """The campaign's repro, three times: two `rail-monitor batch` into one --output at once. One
    run writes the folder and says so; the other fails with one line and deletes nothing."""
    for trial in range(3):
        out = tmp_path / f"out{trial}"
        runs = [subprocess.Popen(["rail-monitor", "batch", str(EXAMPLE_CSV), "--no-report", "--output", str(out)],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
        done = [(p.wait(timeout=300), *p.communicate()) for p in runs]
        ok = [d for d in done if d[0] == 0]
        assert len(ok) == 1, done
        failed = next(d for d in done if d[0] != 0)
        assert "Traceback" not in failed[2] and len(failed[2].strip().splitlines()) == 1, failed[2]
        assert f"recorded to {out}" in ok[0][1]
        assert len(read_bag_passes(out)) > 0
