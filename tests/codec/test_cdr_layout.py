"""The CDR layout shared by bagio's readers and writers: a run of fixed-size fields as struct packs
it (the per-message path) and as the numpy record the column paths read, at every alignment phase."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.codec.cdr_layout import ENCAPSULATION, Run, layout, run_dtype
from rail_monitor.messages.topics import GRAPH_TOPICS

RUNS = sorted({(typename, k) for typename, _ in GRAPH_TOPICS.values()
               for k, item in enumerate(layout(typename)) if isinstance(item, Run)})


@pytest.mark.parametrize(("typename", "k"), RUNS)
def test_a_run_packed_by_struct_reads_back_through_its_numpy_record_at_every_phase(typename, k):
    run = layout(typename)[k]
    rng = np.random.default_rng(k)
    for phase in range(8):
        fields = {name: bool(rng.integers(2)) if code == "?" else int(rng.integers(0, 100)) if code in "bBhHiIqQ"
                  else float(rng.normal()) for name, code in zip(run.names, run.codes, strict=True)}
        buf = bytearray(ENCAPSULATION) + bytes(phase)
        run.encode(buf, fields)
        dtype = run_dtype(run, phase)
        assert len(buf) - 4 - phase == dtype.itemsize
        got = np.frombuffer(bytes(buf), dtype, 1, 4 + phase)[0]
        for name, code in zip(run.names, run.codes, strict=True):
            assert (bool(got[name]) if code == "?" else got[name].item()) == fields[name], (name, phase)
