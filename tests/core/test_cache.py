"""The disk cache of per-site tables (issue 22: the track receptance is paid once per site, not per
command): exact round trip, a key per input, a bad entry rebuilt, read-only maps, no cache where none can be written."""

from __future__ import annotations

import os

import numpy as np

from rail_monitor.core import cache


def _build(counter):
    def build():
        counter.append(1)
        return {"x": np.geomspace(0.05, 2e4, 7), "z": np.array([1 + 2j, np.pi - 1j])}

    return build


def test_a_second_call_reads_the_file_exactly(tmp_path, monkeypatch):
    monkeypatch.setenv("RAIL_MONITOR_CACHE", str(tmp_path))
    calls = []
    first = cache.cached_arrays("t", {"a": 0.1}, _build(calls))
    second = cache.cached_arrays("t", {"a": 0.1}, _build(calls))
    assert len(calls) == 1 and len(list(tmp_path.glob("t_*"))) == 1
    fresh = _build([])()
    for k in first:
        assert np.array_equal(first[k], fresh[k]) and np.array_equal(second[k], fresh[k])
        assert first[k].dtype == second[k].dtype == fresh[k].dtype
    cache.cached_arrays("t", {"a": 0.1 + 1e-12}, _build(calls))  # another input: another entry
    assert len(calls) == 2 and len(list(tmp_path.glob("t_*"))) == 2
    assert not list(tmp_path.glob(".*"))  # nothing left aside


def test_arrays_are_read_only_maps_of_the_files(tmp_path, monkeypatch):
    # A process holds only the pages it touches (the growth table is 24 MB; a live node reads kB).
    monkeypatch.setenv("RAIL_MONITOR_CACHE", str(tmp_path))
    got = cache.cached_arrays("t", {"a": 3}, _build([]))
    for k, a in got.items():
        assert type(a) is np.ndarray and not a.flags.writeable and not a.flags.owndata
        assert isinstance(a.base, np.memmap) and str(a.base.filename) == str(next(tmp_path.glob("t_*")) / f"{k}.npy")


def test_a_corrupt_or_foreign_file_is_rebuilt(tmp_path, monkeypatch):
    monkeypatch.setenv("RAIL_MONITOR_CACHE", str(tmp_path))
    calls = []
    cache.cached_arrays("t", {"a": 1}, _build(calls))
    (entry,) = tmp_path.glob("t_*")
    (entry / "x.npy").write_bytes(b"not an npy")
    assert cache.cached_arrays("t", {"a": 1}, _build(calls))["x"][0] == 0.05 and len(calls) == 2
    assert cache.cached_arrays("t", {"a": 1}, _build(calls))["x"][0] == 0.05 and len(calls) == 2  # replaced
    (entry / "key").write_text(cache.cache_key("t", {"a": 2}))  # an entry that names another key
    assert cache.cached_arrays("t", {"a": 1}, _build(calls))["x"][0] == 0.05 and len(calls) == 3
    assert (entry / "key").read_text() == cache.cache_key("t", {"a": 1})
    (entry / "key").unlink()  # cut short before its key was written
    assert cache.cached_arrays("t", {"a": 1}, _build(calls))["x"][0] == 0.05 and len(calls) == 4
    assert not list(tmp_path.glob(".*"))


def test_a_folder_holding_anything_else_is_not_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv("RAIL_MONITOR_CACHE", str(tmp_path))
    entry = tmp_path / f"t_{cache.cache_key('t', {'a': 1})[:24]}"
    entry.mkdir()
    (entry / "notes.txt").write_text("mine")
    calls = []
    assert cache.cached_arrays("t", {"a": 1}, _build(calls))["x"][0] == 0.05 and len(calls) == 1
    assert (entry / "notes.txt").read_text() == "mine" and not list(tmp_path.glob(".*"))


def test_no_cache_where_the_folder_cannot_be_written(tmp_path, monkeypatch):
    ro = tmp_path / "ro"
    ro.mkdir()
    os.chmod(ro, 0o500)
    monkeypatch.setenv("RAIL_MONITOR_CACHE", str(ro / "sub"))
    calls = []
    try:
        assert len(cache.cached_arrays("t", {"a": 1}, _build(calls))["z"]) == 2
    finally:
        os.chmod(ro, 0o700)


def test_the_rail_receptance_from_the_cache_equals_a_fresh_one(tmp_path, monkeypatch):
    from rail_monitor.corrugation import growth
    from rail_monitor.models import track as tr

    monkeypatch.setenv("RAIL_MONITOR_CACHE", str(tmp_path))
    growth._rail_receptance.cache_clear()
    f, r = growth._rail_receptance(tr.Track())
    growth._rail_receptance.cache_clear()
    f2, r2 = growth._rail_receptance(tr.Track())  # from the file
    assert np.array_equal(r, r2) and np.array_equal(f, f2)
    assert np.array_equal(r, tr.discrete_receptance(f, tr.Track(), position=growth.BAY_POSITIONS))
    growth._rail_receptance.cache_clear()
