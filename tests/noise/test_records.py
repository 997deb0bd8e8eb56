"""The containers of noise predictions: rows put from parts land where they are asked to."""

from dataclasses import replace

import numpy as np

from rail_monitor.noise.records import NoisePrediction, NoiseRows


def _prediction(values: np.ndarray) -> NoisePrediction:
    n = len(values)
    return NoisePrediction("cnossos", np.array([500.0, 1000.0]), ["rail"], values, np.stack([values, -values], 1),
                           np.zeros((n, 2)), np.zeros((n, 2)), values, values, values, values, values[:, None], values)


def test_rows_in_any_order_land_at_their_indices_and_a_run_is_a_block():
    # A class-ordered chunk gives a permutation of a contiguous range: not a block copy.
    rows = NoiseRows(8)
    shuffled = np.array([3, 5, 4, 6])  # first and last as a run's
    rows.put(shuffled, {"cnossos": _prediction(shuffled.astype(float))})
    rows.put(np.array([0, 1, 2]), {"cnossos": _prediction(np.array([0.0, 1.0, 2.0]))})
    rows.put(slice(7, 8), {"cnossos": _prediction(np.array([7.0]))})
    got = rows.predictions()["cnossos"]
    assert got.speed_mps.tolist() == list(range(8)) and got.lp_db[:, 1].tolist() == [-float(i) for i in range(8)]


def test_every_passs_components_at_once_are_each_passs_components():
    # a class without a component (-inf: CNOSSOS-EU's superstructure term on non-freight) leaves it
    # out of its passes' lists; passes alike share one layout
    levels = np.array([[70.0, -np.inf, 60.0], [71.0, 55.0, 61.0], [72.0, -np.inf, 62.0], [73.0, 56.0, 63.0]])
    p = replace(_prediction(np.arange(4.0)), component_names=["track", "superstructure", "vehicle"],
                component_lpaeq_dba=levels)
    for q in (p, replace(p, component_lpaeq_dba=levels[[1, 3]], speed_mps=p.speed_mps[:2])):
        names, values = q.components_of_all()
        for i in range(len(q)):
            assert (names[i], np.asarray(values[i]).tolist()) == q.components(i)
    assert isinstance(q.components_of_all()[1], np.ndarray)   # one layout: one array
