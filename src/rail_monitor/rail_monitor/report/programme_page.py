"""The grinding programme's report for a manager (rail-monitor plan --report): what to grind when,
what it costs and what it saves against grinding every site on a fixed cycle or when its median
forecast says, the options taken, and the risk left; as index.html with the timeline (PNG) and as
programme.pdf (matplotlib's PDF backend)."""

from __future__ import annotations

import html
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from rail_monitor import __version__
from rail_monitor.core.text import printable
from rail_monitor.core.timeutil import iso_day
from rail_monitor.economics.baselines import Priced
from rail_monitor.economics.outlook import WIDE, SiteOutlook
from rail_monitor.economics.programme import Programme, Rules
from rail_monitor.report.page import PAGE_CSS, html_table, text_pages, text_table
from rail_monitor.report.plots import plt
from rail_monitor.report.programme_plot import programme_timeline


def days_text(days: np.ndarray) -> str:
    """P10-P50-P90 days as text ('never' where infinite)."""
    return "-".join(f"{d:.0f}" if np.isfinite(d) else "never" for d in days)


def headline(prog: Programme, rules: Rules, runs: Sequence[Priced]) -> list[str]:
    """The lines a manager reads first: the programme's cost, its saving against each baseline,
    the options it takes and the risk it leaves."""
    programme, *baselines = runs
    out = [f"{len(prog.sites)} sites over {rules.months} months from {iso_day(rules.month_ns(0))}: "
           f"{programme.count} grinding visits, expected cost {programme.cost:,.0f}."]
    for b in baselines:
        saved = b.cost - programme.cost
        share = f" ({100 * abs(saved) / b.cost:.0f} %)" if b.cost > 0 else ""
        verdict = (f"the programme saves {saved:,.0f}{share}" if saved >= 0 else
                   f"the programme costs {-saved:,.0f}{share} more, the price of its risk limit")
        out.append(f"Against {b.name}: {b.count} visits, {b.cost:,.0f}; {verdict}, with {b.lates:.1f} thresholds "
                   "expected to pass before a visit there.")
    taken = {name: prog.option.count(name) for name in dict.fromkeys(prog.option) if name != "grind"}
    if taken:
        out.append("Options taken: " + ", ".join(f"{name} at {n} site(s)" for name, n in taken.items())
                   + " (in force from each site's first visit).")
    out.append(f"Risk left: {programme.lates:.2f} thresholds expected to pass before their visit; each visit's "
               f"risk at most {100 * rules.risk_limit:g} % where capacity and budget allow "
               f"(largest {100 * float(prog.risk.max(initial=0.0)):.1f} %).")
    return out


def by_month(prog: Programme, rules: Rules) -> list[dict]:
    """What to grind when: each month with a visit, and its sites."""
    rows: dict[int, list[str]] = {}
    for site, visits, option in zip(prog.sites, prog.visits, prog.option, strict=True):
        for m in visits:
            rows.setdefault(int(m), []).append(site if option == "grind" else f"{site} ({option})")
    return [{"month": iso_day(rules.month_ns(m))[:7], "visits": len(s), "sites": ", ".join(s)}
            for m, s in sorted(rows.items())]


def by_site(outlooks: Sequence[SiteOutlook], prog: Programme, rules: Rules) -> list[dict]:
    """Each site, earliest due first: its due date, the option and visits chosen, cost and risk."""
    order = sorted(range(len(outlooks)), key=lambda i: outlooks[i].due_day)
    return [{"site": outlooks[i].site_id, "due P50": iso_day(int(outlooks[i].due_ns()[1])),
             "due P10-P90": " to ".join(iso_day(int(d)) for d in outlooks[i].due_ns()[[0, 2]]),
             "cycle P10-P50-P90 [d]": days_text(outlooks[i].cycle_days), "option": prog.option[i],
             "visits": ", ".join(iso_day(rules.month_ns(m))[:7] for m in prog.visits[i]) or "none",
             "expected cost": float(prog.expected_cost[i]), "largest risk [%]": 100 * float(prog.risk[i])}
            for i in order]


def offered(outlooks: Sequence[SiteOutlook]) -> list[dict]:
    """The options beyond grinding each site offers, with their cycle, running cost and effects."""
    return [{"site": o.site_id, "option": c.name, "cycle P10-P50-P90 [d]": days_text(c.cycle_days),
             "running cost a year": c.cost_per_year, "effects": c.effects}
            for o in outlooks for c in o.options if c.name != "grind"]


def write_programme_report(out: Path, outlooks: Sequence[SiteOutlook], prog: Programme, rules: Rules,
                           runs: Sequence[Priced], wide: Sequence[str]) -> list[Path]:
    """Write timeline.png, programme.pdf and index.html into out; returns them, index.html last."""
    from matplotlib.backends.backend_pdf import PdfPages

    out.mkdir(parents=True, exist_ok=True)
    head, months, options = headline(prog, rules, runs), by_month(prog, rules), offered(outlooks)
    sites = by_site(outlooks, prog, rules)
    survey = ([f"Forecasts too wide to plan cheaply (cycle P90 over {WIDE:g} x P10): {', '.join(wide)}; a roughness "
               "survey there narrows K_b's posterior and would cut the visits the risk limit takes."] if wide else [])
    generated = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    title = f"Grinding programme: {len(prog.sites)} sites"
    lines = [title, f"generated {generated} by rail_monitor {__version__}; costs in the site files' unit", "",
             *head, *survey, "", "What to grind when:", *text_table(months), "", "Per site, earliest due first:",
             *text_table(sites)]
    if options:
        lines += ["", "Options offered:", *text_table(options)]
    fig = programme_timeline(outlooks, prog, rules)
    fig.savefig(out / "timeline.png", dpi=110)
    with PdfPages(out / "programme.pdf", metadata={"Title": title, "Creator": f"rail_monitor {__version__}"}) as pdf:
        for page in [*text_pages(lines), fig]:
            pdf.savefig(page)
            plt.close(page)
    body = "".join(f"<p>{html.escape(printable(line))}</p>" for line in [*head, *survey])
    extra = f"<h2>Options offered</h2>{html_table(options)}" if options else ""
    (out / "index.html").write_text(
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
        f"<style>{PAGE_CSS}</style></head><body><h1>{html.escape(title)}</h1><p class=meta>generated {generated} "
        f"by rail_monitor {__version__}; costs in the site files' unit; also as <a href='programme.pdf'>PDF</a></p>"
        f"<div class=head>{body}</div><figure><img src='timeline.png' alt='programme timeline'><figcaption>Each "
        "site's due date (P10-P90, P50 marked) and its visits, earliest due first.</figcaption></figure>"
        f"<h2>What to grind when</h2>{html_table(months)}<h2>Per site</h2>{html_table(sites)}{extra}</body></html>",
        encoding="utf-8")
    return [out / "timeline.png", out / "programme.pdf", out / "index.html"]
