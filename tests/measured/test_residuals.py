"""Measured pass-by noise against its prediction (rail_monitor.measured): the checks that refuse a
bad measurement, the residuals against an independent energy sum, the pairing's independence of
arrival order, and the running baseline against a plain median written here."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from rail_monitor.measured.config import residual_config
from rail_monitor.measured.records import Measurement
from rail_monitor.measured.residuals import INSTRUMENT_SD_DB, SQUEAL, UNPAIRED, Predicted, ResidualTracker
from rail_monitor.noise.config import MODELS, band_centres_hz

BANDS = band_centres_hz()
RNG = np.random.default_rng(4)


def _pair(i: int, excess: float = 0.0) -> tuple[Measurement, list[Predicted]]:
    """Pass i (stamp i s after 2026), predicted flat at 70 dB by both models; measured 1 dB above
    the first model, plus excess in 500-2000 Hz, with 4 vehicle segments."""
    stamp = 1_790_000_000 * 10**9 + i * 10**9
    lp = np.full(len(BANDS), 70.0)
    mid = (BANDS >= 490) & (BANDS <= 2040)
    leq = lp + 1.0 + excess * mid + RNG.normal(0.0, 0.1, len(BANDS))
    m = Measurement(stamp, f"T{i}", 7.5, 1.2, 1, BANDS.copy(), leq, 80.0, 83.0, 85.0, False,
                    ("A", "B", "C", "D"), np.array([80.0, 80.0, 80.0 + excess, 80.0]))
    return m, [*(Predicted(stamp, f"T{i}", model, lp + k, 79.0, 82.0, 84.0) for k, model in enumerate(MODELS)),
               Predicted(stamp, f"T{i}", SQUEAL, np.zeros(0), math.nan, math.nan, math.nan, 2)]


def _tracker(**over) -> ResidualTracker:
    return ResidualTracker(residual_config({f"residual.{k}": v for k, v in over.items()}), BANDS, (7.5, 1.2), MODELS)


@pytest.mark.parametrize("change, why", [
    ({"leq_db": np.where(np.arange(len(BANDS)) == 3, np.nan, 70.0)}, "not finite"),
    ({"lpafmax_dba": 400.0}, "outside 0-150 dB"),
    ({"leq_db": np.full(len(BANDS), -3.0)}, "outside 0-150 dB"),
    ({"band_centre_hz": BANDS * 1.1}, "not a 1/3-octave centre"),
    ({"band_centre_hz": BANDS[:3], "leq_db": np.full(4, 70.0)}, "differ in length"),
    ({"receiver_distance_m": 25.0}, "is not the model's"),
    ({"instrument_class": 3}, "instrument class 3"),
    ({"vehicle_id": ("A",)}, "vehicle_id and vehicle_lpaeq_dba"),
    ({"stamp_ns": 0}, "stamp not set"),
    ({"band_centre_hz": np.full(10**6, 500.0), "leq_db": np.full(10**6, 70.0)}, "more bands than the model's"),
])
def test_a_bad_measurement_is_refused_with_its_reason_and_changes_nothing(change, why):
    t = _tracker()
    m, p = _pair(0)
    assert t.add_measurement(replace(m, **change)) == []
    assert list(t.refused) == [next(k for k in t.refused if why in k)] and not t.queue
    assert len(t.add_predictions(p)) == 0 and t.refused[UNPAIRED] == 0  # nothing waits for it
    assert len(t.add_measurement(m)) == 2                                # the good one still pairs


def test_residuals_equal_an_independent_energy_difference():
    t = _tracker()
    m, p = _pair(0, excess=4.0)
    out = t.add_measurement(m) + t.add_predictions(p)
    assert [r.model for r in out] == list(MODELS) and {r.squeal_risk for r in out} == {2}  # the squeal model's
    r = out[0]
    np.testing.assert_allclose(r.residual_db, m.leq_db - p[0].lp_db, rtol=0, atol=1e-12)
    sel = [i for i, f in enumerate(BANDS) if 500 <= f <= 2000]  # the 500-2000 Hz thirds
    want = 10 * math.log10(sum(10 ** (m.leq_db[i] / 10) for i in sel)) - 10 * math.log10(
        sum(10 ** (p[0].lp_db[i] / 10) for i in sel))
    assert r.residual_mid_db == pytest.approx(want, abs=1e-9)
    assert (r.residual_lpaeq_dba, r.residual_lpafmax_dba, r.residual_tel_dba) == (1.0, 1.0, 1.0)
    assert out[1].residual_lpaeq_dba == 1.0 and out[1].residual_db[0] == pytest.approx(r.residual_db[0] - 1.0)
    # the loudest segment over the energy mean of the four: 84 - 10 lg((3 + 10^0.4) / 4) dB
    assert r.loudest_vehicle_id == "C"
    assert r.loudest_vehicle_excess_db == pytest.approx(84 - 80 - 10 * math.log10((3 + 10**0.4) / 4), abs=1e-9)
    # IEC 61672-1:2013 class 1 acceptance limit at 1 kHz, 1.1 dB, as a rectangular distribution (GUM 4.3.7)
    assert r.measurement_sd_db == pytest.approx(1.1 / math.sqrt(3)) == INSTRUMENT_SD_DB[1]


def test_pairing_gives_the_same_residuals_in_any_arrival_order_a_replay_allows():
    """Predictions in their publisher's order, in bursts; each measurement anywhere before the
    next pass's predictions (before or after its own pass's, which may be far behind)."""
    pairs = [_pair(i, excess=12.0 if i in (30, 31, 47) else 0.0) for i in range(80)]
    ref = _tracker(baseline_passes=25, baseline_min_passes=10)
    want = [r for m, p in pairs for r in ref.add_measurement(m) + ref.add_predictions(p)]
    assert len(want) == 160
    rng = np.random.default_rng(9)
    for _ in range(3):
        t, got, sent = _tracker(baseline_passes=25, baseline_min_passes=10), [], 0
        for i, (m, _) in enumerate(pairs):
            upto = int(rng.integers(sent, i + 1)) if rng.random() < 0.7 else sent  # predictions lag behind
            got += t.add_predictions([q for _, p in pairs[sent:upto] for q in p])
            sent = upto
            got += t.add_measurement(m)
        got += t.add_predictions([q for _, p in pairs[sent:] for q in p])
        assert [(r.stamp_ns, r.model) for r in got] == [(r.stamp_ns, r.model) for r in want] and t.late == 0
        for a, b in zip(got, want, strict=True):
            assert a.excess_mid_db == b.excess_mid_db or (math.isnan(a.excess_mid_db) and math.isnan(b.excess_mid_db))
    # one measurement arriving after later ones were scored is scored on arrival, and counted
    t = _tracker()
    for m, p in pairs[1:5]:
        t.add_measurement(m)
        t.add_predictions(p)
    assert len(t.add_predictions(pairs[0][1]) + t.add_measurement(pairs[0][0])) == 2 and t.late == 1


def test_the_baseline_is_the_running_median_of_the_non_outliers():
    t = _tracker(baseline_passes=20, baseline_min_passes=5, outlier_db=6.0)
    window, mids, ref = [], [], math.nan
    for i in range(60):
        m, p = _pair(i, excess=15.0 if i % 13 == 7 else 0.0)
        r = (t.add_measurement(m) + t.add_predictions(p))[0]
        base = float(np.median(window[-20:])) if len(window) >= 5 else math.nan
        if math.isnan(ref) and len(window) >= 20:
            ref = base
        assert (r.baseline_mid_db == pytest.approx(base, abs=1e-12)) if window[4:] else math.isnan(r.baseline_mid_db)
        if not r.residual_mid_db - base > 6.0:
            window.append(r.residual_mid_db)
        mids.append(r.excess_mid_db)
        assert r.drift_db == pytest.approx(base - ref, abs=1e-12, nan_ok=True)
        assert math.isnan(r.drift_db) == (i < 22)  # full after 20 non-outliers (passes 7 and 20 left out)
    flagged = [i for i, e in enumerate(mids) if e > 6.0]
    assert flagged == [i for i in range(60) if i % 13 == 7 and i > 5]


@pytest.mark.parametrize("size", [1, 2, 7, 20])
def test_the_baseline_median_is_numpys_bit_for_bit(size):
    # The window is kept sorted beside its arrival order; its median must be numpy's of the same
    # values exactly (live and batch compare residuals bit for bit, and earlier versions used numpy's).
    from rail_monitor.measured.residuals import Baseline

    rng = np.random.default_rng(size)
    b = Baseline(size, 1, 6.0)
    values = np.round(rng.normal(0.0, 2.0, 400), 1)  # ties, repeats and outliers
    values[::37] = np.nan
    for v in values.tolist():
        if len(b.window):
            assert b.median() == float(np.median(list(b.window)))
        b.score(v)
        assert sorted(b.window) == b._sorted and len(b.window) <= size


def test_a_pass_measured_twice_or_never_predicted_is_refused():
    t = _tracker()
    m0, p0 = _pair(0)
    m1, p1 = _pair(1)
    ghost = replace(_pair(2)[0], train_id="GHOST")
    m3, p3 = _pair(3)
    assert t.add_measurement(m0) == [] and t.add_measurement(m0) == []
    assert t.refused["pass measured twice"] == 1
    t.add_measurement(ghost)
    assert len(t.add_predictions(p0 + p1)) == 2      # m0 paired; ghost still may come
    assert t.refused[UNPAIRED] == 0
    t.add_measurement(m1)                            # late: its predictions came before it
    t.add_predictions(p3)                            # a later pass predicted by every model: ghost has none
    assert t.refused[UNPAIRED] == 1 and not t.queue
    t.add_measurement(m3)
    assert not t.queue


def test_measurements_waiting_for_passes_are_bounded():
    t = _tracker(held_predictions=10)
    for i in range(12):
        t.add_measurement(_pair(10**6 + i)[0])  # far ahead of every prediction
    assert len(t.queue) == 10 and t.refused["too many measurements waiting for their passes "
                                            "(residual.held_predictions)"] == 2
