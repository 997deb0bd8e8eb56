"""The grinding programme's timeline (matplotlib, Agg backend): a row per site, earliest due first,
its due date's P10-P90 as a bar with the P50 marked, and the programme's visits as markers."""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.economics.outlook import SiteOutlook
from rail_monitor.economics.programme import MONTH_DAYS, Programme, Rules
from rail_monitor.report.plots import dates

MOST_ROWS = 40  # sites drawn (the earliest due); the CSV holds them all


def programme_timeline(outlooks: Sequence[SiteOutlook], prog: Programme, rules: Rules) -> Figure:
    """The timeline of the programme's first MOST_ROWS sites by due date (dates in UTC)."""
    order = sorted(range(len(outlooks)), key=lambda i: outlooks[i].due_day)
    order = order[:MOST_ROWS]
    fig, ax = plt.subplots(figsize=(10, 1.6 + 0.28 * len(order)), layout="constrained")
    end = rules.start_ns + rules.months * MONTH_DAYS * NS_PER_DAY
    for row, i in enumerate(order):
        o = outlooks[i]
        due = [o.newest_ns + min(d, 1e5) * NS_PER_DAY for d in o.due_days]
        lo, mid, hi = (min(max(d, rules.start_ns), end) for d in due)
        ax.plot(dates(np.array([lo, hi], np.int64)), [row, row], color="tab:orange", lw=5, alpha=0.45,
                solid_capstyle="butt", label="due date P10-P90" if row == 0 else None)
        if rules.start_ns <= due[1] <= end:
            ax.plot(dates(int(mid)), row, "|", color="tab:orange", ms=12, mew=2,
                    label="due date P50" if row == 0 else None)
        visits = rules.start_ns + np.asarray(prog.visits[i], float) * MONTH_DAYS * NS_PER_DAY
        ax.plot(dates(visits.astype(np.int64)), np.full(len(visits), row), "v", color="tab:blue", ms=6,
                label="visit (month's start)" if row == 0 else None)
    ax.set_yticks(range(len(order)), [outlooks[i].site_id for i in order])
    ax.invert_yaxis()
    ax.set_xlim(dates(rules.start_ns), dates(int(end)))
    ax.set_xlabel("date (UTC)")
    more = f"; the {len(order)} due first of {len(outlooks)}" if len(outlooks) > len(order) else ""
    ax.set_title(f"grinding programme, {rules.months} months{more}")
    ax.grid(axis="x", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        fig.legend(loc="outside lower center", ncols=3, fontsize="small")
    return fig
