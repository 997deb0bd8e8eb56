"""The disk cache of per-site tables (issue 22: the track receptance is paid once per site, not per
command): exact round trip, a key per input, a bad file rebuilt, no cache where none can be written."""

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
    assert len(calls) == 1 and len(list(tmp_path.glob("t_*.npz"))) == 1
    for k in first:
        assert np.array_equal(first[k], second[k]) and first[k].dtype == second[k].dtype
    cache.cached_arrays("t", {"a": 0.1 + 1e-12}, _build(calls))  # another input: another file
    assert len(calls) == 2 and len(list(tmp_path.glob("t_*.npz"))) == 2


def test_a_corrupt_or_foreign_file_is_rebuilt(tmp_path, monkeypatch):
    monkeypatch.setenv("RAIL_MONITOR_CACHE", str(tmp_path))
    calls = []
    cache.cached_arrays("t", {"a": 1}, _build(calls))
    (path,) = tmp_path.glob("t_*.npz")
    path.write_bytes(b"not an npz")
    assert cache.cached_arrays("t", {"a": 1}, _build(calls))["x"][0] == 0.05 and len(calls) == 2
    other = cache.cache_key("t", {"a": 2})
    np.savez(path, _key=np.array(other), x=np.zeros(1))  # a file that names another key
    assert cache.cached_arrays("t", {"a": 1}, _build(calls))["x"][0] == 0.05 and len(calls) == 3


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
