"""Model outputs taken together (rail_monitor.messages.output_columns): each message's refusal is the
first rule it breaks, stated here message by message, whether a state's columns came as one block
(every state on as many bands) or per state; runs, series and predictions as a loop over the
messages gives them."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.cdr_columns import FEW, read_columns
from rail_monitor.codec.typestore import CORRUGATION_STATE
from rail_monitor.messages import output_columns as sc


def _state(rng, bands, flaw=""):
    wl = np.geomspace(0.02, 0.5, bands)
    f = {"header": {"stamp": {"sec": int(rng.integers(1, 2**31 - 1)), "nanosec": int(rng.integers(0, 10**9))},
                    "frame_id": "site"},
         "last_train_id": f"T{int(rng.integers(1000))}", "wavelength_m": wl.tolist(),
         "amplitude_m": (rng.random(bands) * 1e-5).tolist(), "post_grinding_m": (rng.random(bands) * 1e-6).tolist(),
         "threshold_m": np.full(bands, 1e-5).tolist(), "days_to_threshold": float(rng.random() * 100),
         "grinding_due": bool(rng.random() < 0.5),
         "grinding_due_time": {"sec": int(rng.integers(0, 2**31 - 1)), "nanosec": 0}}
    if flaw == "lengths":
        f["amplitude_m"] = f["amplitude_m"][:-1]
    elif flaw == "wavelength":
        f["wavelength_m"][1] = -1.0
    elif flaw == "amplitude":
        f["post_grinding_m"][0] = float("nan")
    elif flaw == "threshold":
        f["threshold_m"] = f["threshold_m"][:-1] if rng.random() < 0.5 else [0.0] * bands
    elif flaw == "days":
        f["days_to_threshold"] = float("nan") if rng.random() < 0.5 else -1.0
    elif flaw == "stamp":
        f["header"]["stamp"] = {"sec": 0, "nanosec": 0} if rng.random() < 0.5 else {"sec": -5, "nanosec": 0}
    elif flaw == "two":  # a bad wavelength and a bad stamp: the wavelength is named
        f["wavelength_m"][0] = float("inf")
        f["header"]["stamp"] = {"sec": 0, "nanosec": 0}
    elif flaw == "no post":
        f["post_grinding_m"] = []
    return f


def _expected(f):
    """The rules, in the order they are checked, for one state's fields."""
    wl, amp, post, thr = (np.asarray(f[k], float) for k in ("wavelength_m", "amplitude_m", "post_grinding_m",
                                                            "threshold_m"))
    ns = f["header"]["stamp"]["sec"] * 10**9 + f["header"]["stamp"]["nanosec"]
    for bad, why in ((not (len(wl) == len(amp) > 0 and len(post) in (0, len(wl)))), sc.LENGTHS), \
                     (not np.all(np.isfinite(wl) & (wl > 0)), sc.WAVELENGTH), \
                     (not (np.all(np.isfinite(amp) & (amp >= 0)) and np.all(np.isfinite(post) & (post >= 0))),
                      sc.AMPLITUDE):
        if bad:
            return why, why
    for bad, why in ((len(thr) != len(wl) or not np.all(np.isfinite(thr) & (thr > 0))), sc.THRESHOLD), \
                     (np.isnan(f["days_to_threshold"]) or f["days_to_threshold"] < 0, sc.DAYS), \
                     (not (0 < ns < 2**31 * 10**9), sc.STAMP):
        if bad:
            return "", why
    return "", ""


FLAWS = ["", "", "", "lengths", "wavelength", "amplitude", "threshold", "days", "stamp", "two", "no post"]


@pytest.mark.parametrize("n", [3, FEW + 5])
@pytest.mark.parametrize("one_block", [True, False])
def test_each_state_is_refused_for_the_first_rule_it_breaks(n, one_block):
    rng = np.random.default_rng(n + 10 * one_block)
    fields = [_state(rng, 6 if one_block or k % 2 else 7, FLAWS[k % len(FLAWS)] if k else "") for k in range(n)]
    if one_block:   # flaws that change a length would split the block
        fields = [f if len(f["amplitude_m"]) == 6 and len(f["threshold_m"]) == 6 and len(f["post_grinding_m"]) == 6
                  else _state(rng, 6, "amplitude") for f in fields]
    values = read_columns(CORRUGATION_STATE, [serialize(CORRUGATION_STATE, f) for f in fields]).values
    assert isinstance(values.amplitude_m, np.ndarray) == one_block
    want = [_expected(f) for f in fields]
    assert sc.corrugation_refusals(values).tolist() == [w[0] for w in want]
    assert sc.state_refusals(values).tolist() == [w[0] or w[1] for w in want]
    for i, f in enumerate(fields):
        if not want[i][0]:
            c = sc.corrugation(values, i)
            np.testing.assert_array_equal(c.amplitude_m, f["amplitude_m"])
            np.testing.assert_array_equal(c.post_grinding_m, f["post_grinding_m"] or np.zeros(len(f["amplitude_m"])))


@pytest.mark.parametrize("n", [4, FEW + 4])
def test_runs_and_series_follow_the_bands_and_thresholds(n):
    rng = np.random.default_rng(n)
    fields = [_state(rng, 6) for _ in range(n)]
    for k in range(n // 2, n):  # the thresholds change halfway, the bands a pass later
        fields[k]["threshold_m"] = np.full(6, 2e-5).tolist()
    for k in range(n // 2 + 1, n):
        fields[k]["wavelength_m"] = np.geomspace(0.03, 0.6, 6).tolist()
    values = read_columns(CORRUGATION_STATE, [serialize(CORRUGATION_STATE, f) for f in fields]).values
    rows = np.array([k for k in range(n) if k != 1])   # one left out (refused): runs go over what is left
    got = [r.tolist() for r in sc.band_runs(values, rows)]
    assert got == [[0, *range(2, n // 2)], [n // 2], list(range(n // 2 + 1, n))]
    series = sc.corrugation_series(values, np.array(got[-1]))
    np.testing.assert_array_equal(series["amplitude_m"], [fields[k]["amplitude_m"] for k in got[-1]])
    np.testing.assert_array_equal(series["wavelength_m"], fields[-1]["wavelength_m"])
    assert series["stamp_ns"].tolist() == [fields[k]["header"]["stamp"]["sec"] * 10**9
                                           + fields[k]["header"]["stamp"]["nanosec"] for k in got[-1]]
    assert series["grinding_due"].tolist() == [fields[k]["grinding_due"] for k in got[-1]]


@pytest.mark.parametrize("n", [5, FEW + 5])
def test_noise_and_squeal_refusals_and_predictions(n):
    from rail_monitor.measured.residuals import SQUEAL

    rng = np.random.default_rng(n)
    noise, squeal = [], []
    for k in range(n):
        stamp = {"sec": int(rng.integers(1, 2**31 - 1)), "nanosec": int(rng.integers(0, 10**9))}
        header = {"stamp": stamp, "frame_id": "site"}
        levels = {m: float(rng.random() * 90) for m in ("lpaeq_tp_dba", "lpafmax_dba", "tel_dba")}
        noise.append({"header": header, "train_id": f"T{k}", "model": ("cnossos", "mechanics")[k % 2],
                      "lp_db": rng.random(4).tolist(), **levels})
        squeal.append({"header": header, "train_id": f"T{k}", "risk": int(rng.integers(0, 4))})
    # each flaw once, and a model unknown with a level not finite: the model is named
    noise[1]["model"] = "other"
    noise[2]["tel_dba"] = float("inf")
    noise[3]["header"] = {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": "site"}
    noise[4].update(model="", lpafmax_dba=float("nan"))
    squeal[1]["risk"] = 4
    squeal[2]["header"] = {"stamp": {"sec": -1, "nanosec": 0}, "frame_id": "site"}
    squeal[3].update(risk=9, header=noise[3]["header"])
    want_noise = ["", sc.MODEL, sc.LEVEL, sc.STAMP, sc.MODEL] + [""] * (n - 5)
    want_squeal = ["", sc.RISK, sc.STAMP, sc.STAMP] + [""] * (n - 4)
    nv = read_columns("rail_msgs/msg/RollingNoise", [serialize("rail_msgs/msg/RollingNoise", f) for f in noise]).values
    sv = read_columns("rail_msgs/msg/SquealPrediction",
                      [serialize("rail_msgs/msg/SquealPrediction", f) for f in squeal]).values
    assert sc.noise_refusals(nv).tolist() == want_noise
    assert sc.squeal_refusals(sv).tolist() == want_squeal
    ok = np.flatnonzero(sc.noise_refusals(nv) == "")
    for p, k in zip(sc.predictions(nv, ok), ok.tolist(), strict=True):
        f = noise[k]
        assert (p.stamp_ns, p.train_id, p.model) == (f["header"]["stamp"]["sec"] * 10**9
                                                     + f["header"]["stamp"]["nanosec"], f["train_id"], f["model"])
        assert (p.lpaeq_tp_dba, p.lpafmax_dba, p.tel_dba) == (f["lpaeq_tp_dba"], f["lpafmax_dba"], f["tel_dba"])
        np.testing.assert_array_equal(p.lp_db, f["lp_db"])
    got = sc.predictions(sv, np.array([0]))[0]
    assert (got.model, got.squeal_risk, got.train_id) == (SQUEAL, squeal[0]["risk"], "T0")
