"""A batch run's outputs: what the live graph publishes over a history (or one chunk of it), as
arrays and records (no rclpy)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rail_monitor.advice.plan import SpeedAdvice
from rail_monitor.alerts.manager import Alert
from rail_monitor.core.passes import PassTable
from rail_monitor.core.site import Site
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.corrugation.records import Trajectory
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.engine.squeal_site import Calibration
from rail_monitor.measured.observer import Observation
from rail_monitor.measured.records import Measurement
from rail_monitor.measured.residuals import Residual
from rail_monitor.noise.records import NoisePrediction


@dataclass
class SiteOutputs:
    """Model outputs over a history, or over one chunk of it (SiteEngine.feed). Arrays over
    ``accepted`` rows unless named otherwise."""

    site: Site
    passes: PassTable                 # the passes in time order (as the replayer sends them)
    reasons: np.ndarray               # per pass: '' accepted, else why rejected
    accepted: PassTable               # accepted passes, class defaults filled
    squeal: dict[str, np.ndarray]
    trajectory: Trajectory            # state after each counted pass (index: row of ``accepted``)
    noise: dict[str, NoisePrediction]  # per source model
    alerts: list[Alert]               # events, in order (a chunk's: those no later chunk can precede)
    standing: list[Alert]             # after these passes
    advice: SpeedAdvice | None        # on the final state (None for a chunk before the last)
    estimator: CorrugationEstimator   # the state after these passes
    receiver: Any
    left_out: dict[str, int]          # passes the replayer would not send, by reason
    events: list[MaintenanceEvent] = field(default_factory=list)  # surveys and grinding taken, applied or not
    measurements: list[Measurement] = field(default_factory=list)  # measured pass-bys taken, paired or not
    residuals: list[Residual] = field(default_factory=list)        # measured minus predicted, in stamp order
    observations: list[Observation] = field(default_factory=list)  # indirect roughness windows closed
    calibrations: list[Calibration] = field(default_factory=list)  # the squeal model's fits made
    outlooks: list[tuple[MaintenanceEvent, SiteOutlook]] = field(default_factory=list)  # made on each event applied

    @classmethod
    def merged(cls, parts: Sequence[SiteOutputs], held: list[Alert], advice: SpeedAdvice | None) -> SiteOutputs:
        """SiteEngine's chunk results, in order, with what its finish() returned, as the one result of
        the whole history (equal to run_models on it)."""
        last = parts[-1]
        starts = np.cumsum([0, *(len(p.accepted) for p in parts[:-1])]).tolist()
        left_out = sum((Counter(p.left_out) for p in parts), Counter())
        return cls(site=last.site, passes=PassTable.concat([p.passes for p in parts]),
                   reasons=np.concatenate([p.reasons for p in parts]),
                   accepted=PassTable.concat([p.accepted for p in parts]),
                   squeal={k: np.concatenate([p.squeal[k] for p in parts]) for k in last.squeal},
                   trajectory=Trajectory.concat(list(zip(starts, [p.trajectory for p in parts], strict=True))),
                   noise={m: NoisePrediction.concat([p.noise[m] for p in parts]) for m in last.noise},
                   alerts=[a for p in parts for a in p.alerts] + held, standing=last.standing, advice=advice,
                   estimator=last.estimator, receiver=last.receiver, left_out=dict(left_out),
                   events=[e for p in parts for e in p.events],
                   measurements=[m for p in parts for m in p.measurements],
                   residuals=[r for p in parts for r in p.residuals],
                   observations=[o for p in parts for o in p.observations],
                   calibrations=[c for p in parts for c in p.calibrations],
                   outlooks=[o for p in parts for o in p.outlooks])
