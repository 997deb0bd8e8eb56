"""The benchmark harness stays runnable, and batch mode takes any history, an empty one too."""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np

from rail_monitor.batch.run import run_models
from rail_monitor.core.passes import PassTable

from conftest import TOP


def test_the_benchmark_harness_runs_and_batch_equals_the_live_graph(tmp_path):
    out = tmp_path / "bench.md"
    done = subprocess.run([sys.executable, "-m", "bench", "--quick", "--out", str(out)], cwd=TOP,
                          capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    text = out.read_text()
    for section in ("graph against its rclpy ceiling", "live graph as a site runs it",
                    "a live pass through the site engine", "batch", "a busy site's year",
                    "models, per pass", "noise station", "recorder", "memory against passes"):
        assert f"| **{section}** |" in text
    assert re.search(r"\| wayside_monitor start-up to first output \| [0-9.]+ s \|", text), text
    assert re.search(r"\| wayside_monitor start-up to first output, listening \| [0-9.]+ s \|", text), text
    assert re.search(r"\| site engine, one pass fed alone \(feed \+ settle\) \| [0-9.]+ ms \| mean over 60 "
                     r"passes", text), text
    assert re.search(r"\|   of which the engine's own bookkeeping \| -?[0-9.]+ ms \|", text), text
    assert re.search(r"\| live graph, 20 passes/s arriving one at a time \| [0-9]+ % of a core \| latency pass to "
                     r"last output p50 [0-9]+ ms, p95 [0-9]+ ms over 40 passes; by process: "
                     r"corrugation_estimator [0-9]+ %", text), text
    assert re.search(r"\| no-op graph, 20 passes/s arriving one at a time \| [0-9]+ % of a core \| over 40 passes",
                     text), text
    assert re.search(r"\| no-op one-process graph, 20 passes/s arriving one at a time \| [0-9]+ % of a core \| over 40 "
                     r"passes", text), text
    assert re.search(r"\| noise_station hearing 5 passes of 10 s at 48 kHz \| [0-9]+ ms CPU a pass \| heard 5; idle "
                     r"[0-9.]+ % of a core; 100 passes an hour [0-9.]+ % of a core \|", text), text
    assert re.search(r"\| programme, 50 sites x 5 years, no capacity \| [0-9.]+ s \| [0-9,]+ candidate schedules",
                     text), text
    assert re.search(r"\| filling 256 MB new to this process \| [0-9.]+ s \| [0-9.]+ s again", text), text
    assert re.search(r"\| batch streamed to a bag, [0-9,]+ passes \| [0-9,]+ MB \|", text), text
    assert re.search(r"\| export to Parquet, [0-9,]+ passes, in parts of 5,000 passes \| [0-9,]+ MB \|", text), text
    ratio = re.search(r"\| real / ceiling \| ([0-9.]+) \|", text)
    assert ratio and 0.0 < float(ratio.group(1)) < 10.0
    # The live graph's bag against batch mode on the same passes (test_graph checks the full sample).
    row = re.search(r"\| batch against the live graph \(same passes\) \| ([0-9.e+-]+) \| .*levels ([0-9.e+-]+) dB; "
                    r"state count \+0, alert count \+0 \|", text)
    assert row, text
    assert float(row.group(1)) < 1e-9 and float(row.group(2)) < 1e-9


def test_batch_of_an_empty_history_gives_empty_outputs(site_values):
    r = run_models(PassTable.empty(), site_values)
    assert len(r.accepted) == len(r.trajectory) == 0 and r.alerts == [] and r.advice is None
    for out in r.noise.values():
        assert out.lpaeq_tp_dba.shape == (0,) and out.lp_db.shape == (0, len(out.band_centre_hz))
    assert all(np.size(v) == 0 for v in r.squeal.values())


def test_batch_in_chunks_equals_one_call(site_values, sample_passes, monkeypatch):
    # Batch mode bounds its memory by advancing the corrugation state and predicting the noise in
    # chunks of passes; the state carries over, so the chunks give the one call's numbers exactly.
    import rail_monitor.engine.noise_chunks as noise_chunks
    import rail_monitor.engine.site as batch

    whole = run_models(sample_passes, site_values)
    monkeypatch.setattr(batch, "HISTORY_CHUNK", 700)
    monkeypatch.setattr(noise_chunks, "NOISE_CHUNK", 900)
    chunked = run_models(sample_passes, site_values)
    a, b = whole.trajectory, chunked.trajectory
    assert np.array_equal(a.index, b.index) and np.array_equal(a.total_pass_count, b.total_pass_count)
    np.testing.assert_array_equal(b.amplitude, a.amplitude)
    np.testing.assert_array_equal(b.forecast.days_to_threshold, a.forecast.days_to_threshold)
    for name, out in whole.noise.items():
        np.testing.assert_array_equal(chunked.noise[name].lp_db, out.lp_db)
        np.testing.assert_array_equal(chunked.noise[name].lpafmax_dba, out.lpafmax_dba)
    assert chunked.alerts == whole.alerts
