"""What the site's measured squeal says of the squeal model: each friction state's creep curve
re-fitted from a history's measured pass-bys (rail_monitor.squeal.calibration), beside the
configured curve, with the squeal share measured, predicted by the configured curve and by the
fitted one (``rail-monitor predict squeal --history H --fit``; callable from Python too)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from rail_monitor.alerts.config import RISK_NAMES
from rail_monitor.core.friction import FRICTION_NAMES
from rail_monitor.core.passes import PassTable, rejection_reasons, with_class_defaults
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.measured.records import Measurement
from rail_monitor.squeal.calibration import FitConfig, SquealFit, fit_config
from rail_monitor.squeal.predict import predict


def measured_passes(config: SiteConfig, passes: PassTable, measurements: Sequence[Measurement]
                    ) -> tuple[PassTable, np.ndarray, np.ndarray, np.ndarray]:
    """The valid passes measured (class defaults filled, stamp order), each one's squeal flag, its
    tone level [dB re 20 uPa] (NaN: not measured) and the microphone's distance [m]."""
    ok = passes.take(rejection_reasons(passes, config.site) == "")
    by_key = {m.key: m for m in measurements}
    rows = [i for i, key in enumerate(zip(ok.stamp_ns.tolist(), ok.train_id.tolist(), strict=True)) if key in by_key]
    table = with_class_defaults(ok.take(np.array(rows, dtype=np.int64)), config.site)
    ms = [by_key[(int(s), str(t))] for s, t in zip(table.stamp_ns, table.train_id, strict=True)]
    return (table, np.array([m.squeal_detected for m in ms], bool), np.array([m.squeal_level_db for m in ms]),
            np.array([m.receiver_distance_m for m in ms]))


def fit_squeal(values: Mapping[str, Any], passes: PassTable, measurements: Sequence[Measurement],
               levels: bool = True, cfg: FitConfig | None = None) -> tuple[SquealFit, list[dict[str, Any]]]:
    """The fit on every measured pass (levels: use the measured tone levels, else occurrence alone),
    and a row per friction state measured: the configured and fitted curves, the passes and the
    squeal share measured, predicted by the configured curve and by the fit (its predictive mean)."""
    config = SiteConfig.from_values(values)
    if cfg is None:  # the site's prior (squeal.fit_prior_*), squealing counted as the alerts count it
        cfg = fit_config(config.squeal, RISK_NAMES.index(config.alerts.squeal_min_risk))
    table, flags, level, distance = measured_passes(config, passes, measurements)
    fit = SquealFit(config.site, config.squeal, cfg)
    fit.observe(table, flags, level if levels else np.full(len(table), np.nan), distance)
    for code in FRICTION_NAMES:
        fit.refine(code)
    prior_risk = predict(config.squeal, config.site, table)["risk"] >= cfg.min_risk
    rows = []
    for code, name in FRICTION_NAMES.items():
        mine = table.friction_state == code
        if not mine.any():
            continue
        q = fit.quantiles(code)
        k1_0, k2_0 = (float(x[0]) for x in config.site.contact.creep(np.array([code])))
        rows.append({"friction_state": name, "k1": k1_0, "k2": k2_0, "k1_p10_p50_p90": q.k1,
                     "k2_p10_p50_p90": q.k2, "passes": q.passes, "measured_share": float(flags[mine].mean()),
                     "configured_share": float(prior_risk[mine].mean()),
                     "fitted_share": fit.predicted_share(table.take(np.flatnonzero(mine)), code)})
    return fit, rows
