"""Batch mode: the site engine over a whole pass history in one call, vectorised (no rclpy).

Gives what the live graph publishes, pass for pass (rail_monitor.engine.site: the same engine the
live graph runs, fed the history at once); :mod:`rail_monitor.batch.bag` records it chunk by chunk
as the live graph is recorded.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.engine.result import SiteOutputs
from rail_monitor.engine.site import SiteEngine
from rail_monitor.measured.records import Measurement


def run_models(passes: PassTable, values: Mapping[str, Any], estimator: CorrugationEstimator | None = None,
               threads: int = 0, events: Sequence[MaintenanceEvent] = (),
               measurements: Sequence[Measurement] = ()) -> SiteOutputs:
    """Every model over the history ``passes`` for the site of the flat parameter ``values`` in one
    call (estimator, threads, events, measurements: as for SiteEngine)."""
    run = SiteEngine(values, estimator, threads, events, measurements)
    out = run.feed(passes)
    held, advice = run.finish()
    return replace(out, alerts=out.alerts + held, advice=advice, left_out=dict(run.left_out),
                   events=out.events + run.trailing_events, measurements=out.measurements + run.trailing_measurements)
