"""The friction modifier's effect on squeal, for the report: before and after an applicator's
start where the bag holds one (rail_msgs/FrictionApplicator), else the friction states compared.

Before and after: the processed passes stamped before the first start, against those after it
(up to the applicator's next stop, if any): all of them, and those on the dry rail (dry or on the
modifier; wet and contaminated passes left out, as weather and leaf fall change squeal more than
a modifier does and need not be alike on both sides). Per side:
the share predicted to squeal (risk at or above the alerts' ``squeal_min_risk``), the share the
station flagged, and two levels: the squeal model's level at its receiver (a quiet pass counts at
the model's background, so a pass that stops squealing counts as the fall it makes) and, where
measured, the station's pass-by LpAFmax. Each is an energy mean over every pass of the side (the
exposure) and over its loudest passes, as many as the share predicted to squeal before the start
(the passes a modifier is for: before, the squealing ones; after, as many of the loudest, so a
pass that no longer squeals is compared as it now sounds). The loudest passes' cut (before minus
after) is set against the 6.3-22.8 dB(A) Eadie and Santoro measured with friction modifiers at
transit curves. The model's level of a pass is its squeal's energy sum with the
background (``squeal.background_level_dba``), as its friction-modifier benefit is.

References
----------
.. [1] D. T. Eadie, M. Santoro, "Top-of-rail friction control for curve noise mitigation and
   corrugation rate reduction", J. Sound Vib. 293 (2006) 747-757: squeal cut by 6.3-22.8 dB(A).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from rail_monitor.core.friction import (
    ACTION_START,
    ACTION_STOP,
    FRICTION_DRY,
    FRICTION_MODIFIER,
    FRICTION_NAMES,
    ApplicatorEvent,
)
from rail_monitor.core.timeutil import format_local_ns
from rail_monitor.report.tables import finite_mean, heard_flags, processed, squealing

FM_CUT_PUBLISHED_DBA = (6.3, 22.8)  # Eadie & Santoro (2006): friction modifiers at transit curves
SIDES = ("before the start", "after the start")
RAILS = ("all passes", "dry rail (wet and contaminated left out)")
PREDICTED_LEVEL = "squeal level, energy mean of all passes, predicted [dB(A)]"
PREDICTED_LOUDEST = "squeal level, energy mean of the loudest, predicted [dB(A)]"
MEASURED_LEVEL = "pass-by LpAFmax, energy mean, measured [dB(A)]"
MEASURED_LOUDEST = "pass-by LpAFmax, energy mean of the loudest, measured [dB(A)]"


def by_state(t: Mapping[str, np.ndarray], lim: Mapping[str, Any]) -> list[dict]:
    """Squeal per friction state, where the history has passes on the friction modifier and on
    another state (else an empty list): the passes, the share squealing as predicted and, where
    measured, as the station heard it, the mean level of the squealing, and the cut the model
    predicts a friction modifier makes on the squealing passes (mean of their benefit).

    A comparison of friction states, for a bag without an applicator's start: where states mix
    from the first day the first friction-modifier pass says nothing of one (its 'before' may be a
    single pass)."""
    ok = processed(t)
    sq = squealing(t, lim["squeal_min_risk"])
    fm = ok & (t["friction_state"] == FRICTION_NAMES[FRICTION_MODIFIER])
    if not fm.any() or fm.sum() == ok.sum():
        return []
    heard = t.get("measured_squeal_detected")
    rows = []
    for name in FRICTION_NAMES.values():
        m = ok & (t["friction_state"] == name)
        if not m.any():
            continue
        row = {"friction state": name, "passes": int(m.sum()),
               "squealing, predicted [%]": 100.0 * (sq & m).sum() / m.sum()}
        if heard is not None:
            row["squealing, measured [%]"] = _heard_percent(heard, m)
        row["squeal level, mean of squealing [dB(A)]"] = finite_mean(t["squeal_level_dba"][sq & m])
        benefit = t.get("squeal_friction_modifier_benefit_db")
        row["friction-modifier cut, predicted, mean of squealing [dB(A)]"] = (
            finite_mean(np.asarray(benefit[sq & m], float)) if benefit is not None and name != FRICTION_NAMES[
                FRICTION_MODIFIER] else float("nan"))
        rows.append(row)
    return rows


def first_start(events: Sequence[ApplicatorEvent]) -> tuple[ApplicatorEvent, int] | None:
    """The applicator's first start and the stamp its run ends [ns] (its next stop; the end of
    time without one), or None where the bag holds no start."""
    start = next((e for e in events if e.action == ACTION_START), None)
    if start is None:
        return None
    stop = next((e.stamp_ns for e in events if e.action == ACTION_STOP and e.stamp_ns > start.stamp_ns),
                np.iinfo(np.int64).max)
    return start, stop


def before_after(t: Mapping[str, np.ndarray], lim: Mapping[str, Any], events: Sequence[ApplicatorEvent]
                 ) -> list[dict]:
    """Rows before and after the applicator's first start, and their difference, over all passes
    and over the dry rail's (empty without a start); units in the keys. The loudest passes of each
    side are as many of its passes as the share predicted to squeal before the start (the passes a
    modifier is for)."""
    run = first_start(events)
    if run is None:
        return []
    (start, stop), ok = run, processed(t)
    stamps = np.asarray(t["stamp_ns"], np.int64)
    dry = np.isin(t["friction_state"], [FRICTION_NAMES[FRICTION_DRY], FRICTION_NAMES[FRICTION_MODIFIER]])
    rows = []
    for rail, group in zip(RAILS, (ok, ok & dry), strict=True):
        sides = (group & (stamps < start.stamp_ns), group & (stamps > start.stamp_ns) & (stamps < stop))
        rows += _compared(t, lim, rail, sides)
    return rows


def _compared(t: Mapping[str, np.ndarray], lim: Mapping[str, Any], rail: str,
              sides: tuple[np.ndarray, np.ndarray]) -> list[dict]:
    """The rows of one group of passes: before, after, and the cut."""
    sq = squealing(t, lim["squeal_min_risk"])
    heard = t.get("measured_squeal_detected")
    share = (sq & sides[0]).sum() / max(int(sides[0].sum()), 1)
    rows = []
    for side, m in zip(SIDES, sides, strict=True):
        n = int(m.sum())
        row: dict[str, Any] = {"rail": rail, "passes": side, "count": n,
                               "squealing, predicted [%]": 100.0 * (sq & m).sum() / n if n else float("nan")}
        if heard is not None:
            row["squealing, measured [%]"] = _heard_percent(heard, m)
        squeal = np.nan_to_num(np.asarray(t["squeal_level_dba"][m], float), nan=-np.inf)  # NaN: stable
        level = 10.0 * np.log10(10.0 ** (squeal / 10.0) + 10.0 ** (lim["squeal_background_dba"] / 10.0))
        row[PREDICTED_LEVEL] = energy_mean(level)
        row[PREDICTED_LOUDEST] = energy_mean(loudest(level, share))
        if heard is not None:
            measured = np.asarray(t["measured_lpafmax_dba"][m], float)
            row[MEASURED_LEVEL] = energy_mean(measured)
            row[MEASURED_LOUDEST] = energy_mean(loudest(measured, share))
        rows.append(row)
    cut = {k: v - rows[1][k] for k, v in rows[0].items() if k not in ("rail", "passes", "count")}
    return [*rows, {"rail": rail, "passes": "cut (before minus after)", "count": "", **cut}]


def loudest(level_db: np.ndarray, share: float) -> np.ndarray:
    """The loudest share of the finite levels (at least one where there are any) [dB]."""
    x = np.sort(np.asarray(level_db, float)[np.isfinite(level_db)])[::-1]
    return x[:max(1, round(share * len(x)))] if len(x) else x


def energy_mean(level_db: np.ndarray) -> float:
    """10 lg of the mean of 10^(L/10) over the finite levels [dB] (NaN: none)."""
    x = np.asarray(level_db, float)
    x = x[np.isfinite(x)]
    return float(10.0 * np.log10(np.mean(10.0 ** (x / 10.0)))) if len(x) else float("nan")


def _heard_percent(heard: np.ndarray, rows: np.ndarray) -> float:
    """The share of the measured passes among rows the station flagged squealing [%] (NaN: none)."""
    measured, flags = heard_flags(heard)
    measured &= rows
    return 100.0 * flags[measured].mean() if measured.any() else float("nan")


def summary(by_state_rows: list[dict], applicator_rows: list[dict], events: Sequence[ApplicatorEvent],
            zone: str) -> dict[str, Any] | None:
    """The headline's friction-modifier numbers (summary.json): before and after the applicator's
    start where there is one, else friction states compared (None: neither)."""
    published = list(FM_CUT_PUBLISHED_DBA)
    if applicator_rows:
        start, _ = first_start(events)
        (all_before, all_after, all_cut), (before, after, cut) = applicator_rows[:3], applicator_rows[3:]
        return {"compared": "before and after the applicator's start, on the dry rail",
                "start": format_local_ns(start.stamp_ns, zone), "product": start.product,
                "passes": [before["count"], after["count"]],
                "predicted_percent": [before["squealing, predicted [%]"], after["squealing, predicted [%]"]],
                "measured_percent": [r.get("squealing, measured [%]") for r in (before, after)],
                "loudest_percent": before["squealing, predicted [%]"],
                "predicted_cut_dba": cut[PREDICTED_LOUDEST], "measured_cut_dba": cut.get(MEASURED_LOUDEST),
                "all_passes_predicted_percent": [all_before["squealing, predicted [%]"],
                                                 all_after["squealing, predicted [%]"]],
                "all_passes_predicted_cut_dba": all_cut[PREDICTED_LOUDEST], "published_cut_dba": published}
    rows = {r["friction state"]: dict(r) for r in by_state_rows}
    if not rows:
        return None
    on = rows.pop(FRICTION_NAMES[FRICTION_MODIFIER])
    off = list(rows.values())
    n = sum(r["passes"] for r in off)
    cuts = [(r["passes"], r["friction-modifier cut, predicted, mean of squealing [dB(A)]"]) for r in off]
    cuts = [(k, c) for k, c in cuts if np.isfinite(c)]
    return {"compared": "friction states (no applicator start in the bag)",
            "on_squealing_percent": on["squealing, predicted [%]"],
            "off_squealing_percent": sum(r["passes"] * r["squealing, predicted [%]"] for r in off) / n,
            "on_measured_percent": on.get("squealing, measured [%]"),
            "off_measured_percent": _pooled(off, "squealing, measured [%]"),
            "predicted_cut_dba": sum(k * c for k, c in cuts) / sum(k for k, _ in cuts) if cuts else None,
            "published_cut_dba": published}


def _pooled(rows: list[dict], key: str) -> float | None:
    """A share [%] pooled over rows by their passes (None where no row has it)."""
    have = [(r["passes"], r[key]) for r in rows if np.isfinite(r.get(key, np.nan))]
    return sum(k * v for k, v in have) / sum(k for k, _ in have) if have else None


def _fell(cut_db: float) -> str:
    return f"fell by {cut_db:.1f} dB(A)" if cut_db >= 0 else f"rose by {-cut_db:.1f} dB(A)"


def _finite(x: Any) -> bool:
    return x is not None and bool(np.isfinite(x))


def headline_line(fm: Mapping[str, Any]) -> str:
    """The headline's sentence on the friction modifier."""
    lo, hi = fm["published_cut_dba"]
    published = f"(published: {lo:g}-{hi:g} dB(A))"
    if "start" in fm:
        (nb, na), (pb, pa), (mb, ma) = fm["passes"], fm["predicted_percent"], fm["measured_percent"]
        product = f" ({fm['product']})" if fm["product"] else ""
        if not (nb and na):
            return (f"Friction modifier: the applicator started {fm['start']}{product}, with {nb} passes before "
                    f"and {na} after it: nothing to compare.")
        heard = f"; the station heard {mb:.1f} % and {ma:.1f} %" if _finite(mb) and _finite(ma) else ""
        measured = (f", the measured LpAFmax of as many loudest passes {_fell(fm['measured_cut_dba'])}"
                    if _finite(fm["measured_cut_dba"]) else "")
        ab, aa = fm["all_passes_predicted_percent"]
        return (f"Friction modifier, before and after the applicator's start {fm['start']}{product}, on the dry "
                f"rail (wet and contaminated passes left out: weather and leaf fall are not the modifier's): "
                f"{pb:.1f} % of {nb} passes predicted to squeal before, {pa:.1f} % of {na} after{heard}; the "
                f"model's squeal level of the loudest {fm['loudest_percent']:.1f} % of passes "
                f"{_fell(fm['predicted_cut_dba'])}{measured} {published}. Over all passes: {ab:.1f} % before, "
                f"{aa:.1f} % after, the loudest {_fell(fm['all_passes_predicted_cut_dba'])}.")
    heard = (f"; the station heard {fm['on_measured_percent']:.1f} % against {fm['off_measured_percent']:.1f} %"
             if _finite(fm["on_measured_percent"]) and _finite(fm["off_measured_percent"]) else "")
    cut = (f"; on the squealing passes the model predicts a cut of {fm['predicted_cut_dba']:.1f} dB(A) {published}"
           if fm["predicted_cut_dba"] is not None else "")
    return (f"Friction modifier, friction states compared (the bag holds no applicator start): "
            f"{fm['on_squealing_percent']:.1f} % of passes on the modifier squeal against "
            f"{fm['off_squealing_percent']:.1f} % on the other states{heard}{cut}.")
