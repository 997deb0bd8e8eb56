"""The report folder of a run: a page for management (the headline, per-class tables, the daily
timeline, the friction-modifier comparison, the squealing trains) with an appendix for engineers
(model figures, site parameters, alerts, rejections), as index.html with PNG figures and as
report.pdf (matplotlib's PDF backend), plus summary.json (the headline numbers) and
squealing_trains.csv (every squealing pass)."""

from __future__ import annotations

import html
import json
import math
from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from rail_monitor import __version__
from rail_monitor.alerts.config import KIND_NAMES
from rail_monitor.core.text import jsonable, printable
from rail_monitor.core.timeutil import NS_PER_DAY, format_local_ns
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.report import friction_modifier
from rail_monitor.report import plots as report_plots
from rail_monitor.report import tables as report_tables
from rail_monitor.report.run_data import RunData
from rail_monitor.report.run_tables import pass_table

PAGE_CSS = """body{font-family:system-ui,sans-serif;max-width:1150px;margin:2em auto;color:#222}
h1{margin-bottom:0} .meta{color:#555;font-size:90%} img{max-width:100%}
table{border-collapse:collapse;margin:0.5em 0 1.2em} th,td{border:1px solid #ccc;padding:3px 7px;font-size:88%}
th{background:#f2f2f2;text-align:left} td.n{text-align:right} .head{font-size:110%;line-height:1.5}
figure{margin:1em 0} figcaption{color:#444;font-size:92%}"""


def _cell(key: str, v: Any) -> tuple[str, bool]:
    """A value as table text, and whether it is a number (right-aligned)."""
    if isinstance(v, (bool, np.bool_)):
        return ("yes" if v else "no"), False
    if isinstance(v, (int, np.integer)):
        return f"{int(v)}", True
    if isinstance(v, (float, np.floating)):
        if math.isnan(v):
            return "–", True
        if math.isinf(v):
            return "never", True
        return (f"{v:.2f}" if "µm" in key else f"{v:.1f}"), True
    return printable(v), False


def html_table(rows: list[dict], limit: int | None = None) -> str:
    if not rows:
        return "<p>None.</p>"
    keys = list(rows[0])
    head = "".join(f"<th>{html.escape(k)}</th>" for k in keys)
    body = []
    for r in rows[:limit]:
        cells = (_cell(k, r.get(k)) for k in keys)
        body.append("<tr>" + "".join(f"<td{' class=n' if num else ''}>{html.escape(text)}</td>"
                                     for text, num in cells) + "</tr>")
    more = f"<p>... and {len(rows) - limit} more.</p>" if limit is not None and len(rows) > limit else ""
    return f"<table><tr>{head}</tr>{''.join(body)}</table>{more}"


def text_table(rows: list[dict], limit: int | None = None) -> list[str]:
    if not rows:
        return ["  none"]
    keys = list(rows[0])
    cells = [[_cell(k, r.get(k))[0] for k in keys] for r in rows[:limit]]
    width = [max(len(k), *(len(c[i]) for c in cells)) for i, k in enumerate(keys)]
    return ["  " + "  ".join(k.ljust(w) for k, w in zip(keys, width, strict=True))] + \
        ["  " + "  ".join(c.ljust(w) for c, w in zip(row, width, strict=True)) for row in cells]


def headline(run: RunData, t: Mapping[str, np.ndarray], lim: Mapping[str, Any], tables: Mapping[str, list],
             zone: str) -> dict[str, Any]:
    """The numbers a manager reads first (also summary.json)."""
    ok = t["status"] == "processed"
    sq = report_tables.squealing(t, lim["squeal_min_risk"]) & ok
    first, last = (format_local_ns(int(f(t["stamp_ns"])), zone) for f in (np.min, np.max))
    out: dict[str, Any] = {
        "period": f"{first} to {last}",
        "days": float(np.ptp(t["stamp_ns"]) / NS_PER_DAY), "passes": len(ok), "processed": int(ok.sum()),
        "rejected": int((~ok).sum()), "squealing_passes": int(sq.sum()),
        "squealing_share_percent": 100.0 * sq.sum() / max(ok.sum(), 1), "squeal_min_risk": lim["squeal_min_risk"],
        "loudest_squeal_dba": float(np.nanmax(t["squeal_level_dba"][sq])) if sq.any() else None,
        "noise": tables["noise"], "alerts_raised": sum(a.active for a in run.alerts)}
    outlook = tables["outlook"]
    if outlook:
        worst = next(r for r in outlook if r["forecast"] == report_tables.FULL_FORECAST)
        out["grinding"] = {"band_mm": worst["band [mm]"], "percent_of_threshold": worst["of threshold [%]"],
                           "days": worst["days"], "date": worst["date"],
                           "date_range": worst["date range (traffic P90-P10)"],
                           "due": bool(run.states["grinding_due"][-1])}
    fm = friction_modifier.summary(tables["friction"], tables.get("applicator", []), run.applicator, zone)
    if fm:
        out["friction_modifier"] = fm
    return out


def _headline_lines(h: Mapping[str, Any], lim: Mapping[str, Any]) -> list[str]:
    lines = [f"Period: {h['period']} ({h['days']:.1f} days), {h['processed']} passes processed, "
             f"{h['rejected']} rejected."]
    g = h.get("grinding")
    if g:
        when = "now" if g["due"] and g["days"] <= 0 else f"{g['date']} (in {g['days']:.0f} days)"
        lines.append(f"Grinding {'DUE ' if g['due'] else ''}{when}: the {g['band_mm']:.1f} mm band, at "
                     f"{g['percent_of_threshold']:.0f} % of its threshold"
                     + (f"; from the spread of weekly traffic: {g['date_range']}." if g["date_range"] else "."))
    lines.append(f"Squeal: {h['squealing_passes']} passes ({h['squealing_share_percent']:.1f} %) at risk "
                 f"{h['squeal_min_risk']} or above" + (f", loudest {h['loudest_squeal_dba']:.1f} dB(A)."
                                                       if h["loudest_squeal_dba"] is not None else "."))
    for n in h["noise"]:
        lines.append(f"Noise ({n['model']} model, {n['metric']}): median {n['P50 [dB(A)]']:.1f}, P95 "
                     f"{n['P95 [dB(A)]']:.1f} dB(A) against the limit of {n['limit [dB(A)]']:g} dB(A); "
                     f"{n['above limit [%]']:.1f} % of passes above it.")
    if h.get("friction_modifier"):
        lines.append(friction_modifier.headline_line(h["friction_modifier"]))
    lines.append(f"Alerts raised: {h['alerts_raised']}.")
    return lines


def write_report(run: RunData, cfg: SiteConfig, out: Path, figures_extra: Mapping[str, Any],
                 site_text: str) -> list[Path]:
    """Write the report folder; returns the files written (index.html last).

    figures_extra: the model curves the bag does not hold (``before``/``after`` spectra and squeal
    ``curves`` of a reference pass), from rail_monitor.report.summary."""
    from matplotlib.backends.backend_pdf import PdfPages

    out.mkdir(parents=True, exist_ok=True)
    site = cfg.site
    zone = site.time_zone
    t = pass_table(run, cfg).as_dict()
    lim = report_tables.limits(cfg)
    models = list(run.noise)
    tables = {"outlook": report_tables.grinding_outlook(run, t, zone),
              "noise": report_tables.noise_percentiles(t, lim, models),
              "classes": report_tables.by_class(t, lim, models),
              "applicator": friction_modifier.before_after(t, lim, run.applicator),
              "squealers": report_tables.squealing_trains(t, lim), "advice": report_tables.speed_advice(run),
              "offenders": report_tables.repeat_offenders(t, cfg, zone),
              "squeal_angles": report_tables.squeal_by_angle(t, lim),
              "repeat_squealers": report_tables.repeat_squealers(run.alerts, zone),
              "squeal_fits": report_tables.squeal_fits(run.squeal_fits, zone)}
    tables["friction"] = [] if tables["applicator"] else friction_modifier.by_state(t, lim)
    head = headline(run, t, lim, tables, zone)
    figures = [("timeline", "Passes and squealing passes per day, and the day's highest pass-by level against "
                "the limit.", report_plots.timeline(report_tables.daily(t, lim, models, zone), models, lim, zone))]
    if run.states:
        figures.append(("corrugation", "Corrugation growth per wavelength band, with thresholds and the forecast.",
                        report_plots.corrugation(run.states, zone)))
    if run.noise:
        figures.append(("noise", "Pass-by level per pass by vehicle class, with the limit; spectra of a "
                        "reference pass before and after roughness growth.",
                        report_plots.noise(t, models, lim, figures_extra["before"], figures_extra["after"], zone)))
    if len(run.squeal.get("risk", ())):
        figures.append(("squeal", "Squeal amplitude against crabbing velocity: every pass and the model per "
                        "friction state.", report_plots.squeal(run.squeal, figures_extra["curves"])))
    if run.squeal_fits:
        figures.append(("squeal_fits", "The squeal model's creep curves as the measured squeal fitted them, per "
                        "friction state: P50 and the P10-P90 band at each fit, the configured curve dashed.",
                        report_plots.squeal_fits(run.squeal_fits, zone)))
    if run.residuals:
        figures.append(("measured", "Measured pass-by noise against the prediction, and the 500-2000 Hz residual "
                        "against the site's running baseline (the wheel-defect and drift alerts' reference).",
                        report_plots.measured(t, list(run.residuals), cfg.alerts.residual_model,
                                              zone)))
    figures.append(("speeds", "Speed distributions, shares of train passes: the history, the recent passes, "
                    "and the advised distribution (per class in the speed advice table).",
                    report_plots.speeds(run.passes.speed_mps, run.advisory)))
    generated = datetime.now(UTC)
    meta = {"site_id": site.site_id, "time_zone": zone, "software_version": __version__,
            "generated_utc": generated.strftime("%Y-%m-%dT%H:%M:%SZ"),
            "generated_local": format_local_ns(int(generated.timestamp()) * 10**9, zone), "bag": str(run.bag),
            "site_file": site_text}
    files = []
    with PdfPages(out / "report.pdf", metadata={"Title": f"rail_monitor report: {site.site_id}",
                                                "Creator": f"rail_monitor {__version__}"}) as pdf:
        for page in _pdf_text_pages(head, tables, lim, meta, run):
            pdf.savefig(page)
            report_plots.plt.close(page)
        for name, _, fig in figures:
            fig.savefig(out / f"{name}.png", dpi=110)
            pdf.savefig(fig)
            report_plots.plt.close(fig)
            files.append(out / f"{name}.png")
    _write_csv(tables["squealers"], out / "squealing_trains.csv")
    (out / "summary.json").write_text(json.dumps(jsonable({**meta, **head, "grinding_outlook": tables["outlook"],
                                                           "classes": tables["classes"]}), indent=1,
                                                 allow_nan=False), encoding="utf-8")
    page = out / "index.html"
    listen = figures_extra.get("listen", [])
    page.write_text(_html(run, cfg.values, head, tables, lim, figures, meta, listen), encoding="utf-8")
    audio = [out / r[k].split(" ")[0] for r in listen for k in ("predicted", "measured") if r[k]]
    return [*files, *audio, out / "report.pdf", out / "squealing_trains.csv", out / "summary.json", page]


def _write_csv(rows: list[dict], path: Path) -> None:
    import pandas as pd

    pd.DataFrame(rows, columns=list(rows[0]) if rows else ["train_id"]).to_csv(path, index=False)


def _pdf_text_pages(head, tables, lim, meta, run) -> list:
    lines = [f"rail_monitor report: {meta['site_id']}", f"generated {meta['generated_local']} by rail_monitor "
             f"{meta['software_version']}; times in {meta['time_zone']}", ""]
    lines += [*_headline_lines(head, lim), "", "Per vehicle class:", *text_table(tables["classes"])]
    lines += ["", "Grinding outlook per band:", *text_table(tables["outlook"], 8)]
    if tables["friction"]:
        lines += ["", "Friction modifier, squeal per friction state:", *text_table(tables["friction"])]
    if tables["applicator"]:
        lines += ["", "Friction modifier, before and after the applicator's start:",
                  *text_table(tables["applicator"])]
    if tables["advice"]:
        lines += ["", "Speed advice per class (at its recent mean speed):", *text_table(tables["advice"])]
    lines += ["", f"Loudest squealing trains (of {len(tables['squealers'])}, all in squealing_trains.csv):"]
    lines += text_table(tables["squealers"], 15)
    return text_pages(lines)


def text_pages(lines: list[str], per_page: int = 58) -> list:
    """Lines of monospaced text as A4 landscape figures, per_page lines each (a PDF's text pages)."""
    pages = []
    for k in range(0, len(lines), per_page):
        fig = report_plots.plt.figure(figsize=(11.69, 8.27))
        fig.text(0.03, 0.97, "\n".join(lines[k:k + per_page]), family="monospace", fontsize=6.3, va="top")
        pages.append(fig)
    return pages


def _listen_html(rows: list[dict]) -> str:
    """The loudest passes, each with its predicted audio and its recording where kept."""
    if not rows:
        return ""

    def player(src: str) -> str:
        if not src:
            return "not recorded"
        path, _, note = src.partition(" ")
        return f'<audio controls preload="none" src="{html.escape(path)}"></audio> {html.escape(note)}'

    keys = [k for k in rows[0] if k not in ("predicted", "measured")]
    head = "".join(f"<th>{html.escape(k)}</th>" for k in (*keys, "predicted", "measured"))
    body = "".join("<tr>" + "".join(f"<td{' class=n' if num else ''}>{html.escape(text)}</td>"
                                    for text, num in (_cell(k, r[k]) for k in keys))
                   + f"<td>{player(r['predicted'])}</td><td>{player(r['measured'])}</td></tr>" for r in rows)
    return (f"<h2>Listen: the loudest passes, predicted and recorded</h2><table><tr>{head}</tr>{body}</table>"
            "<p class=\"meta\">The prediction made audible: each source's band noise moving past the microphone "
            "with its spreading and Doppler shift, and the squeal's tone where the model finds the pass unstable. "
            "Every file on one scale (full scale 120 dB re 20 µPa), so louder sounds louder.</p>")


def _html(run, values, head, tables, lim, figures, meta, listen=()) -> str:
    e = html.escape
    lines = "".join(f"<li>{e(x)}</li>" for x in _headline_lines(head, lim))
    alerts = [{"pass time (local)": format_local_ns(a.stamp_ns, meta["time_zone"], seconds=True),
               "event": "raised" if a.active else "cleared", "kind": KIND_NAMES.get(a.kind, str(a.kind)),
               "about": a.key, "summary": a.summary} for a in run.alerts]
    params = [{"parameter": k, "value": v if not isinstance(v, list) else ", ".join(map(str, v))}
              for k, v in sorted(values.items())]
    figs = {name: (caption, name) for name, caption, _ in figures}

    def fig(name: str) -> str:
        if name not in figs:
            return ""
        caption, stem = figs[name]
        return f'<figure><img src="{stem}.png" alt="{e(caption)}"><figcaption>{e(caption)}</figcaption></figure>'

    friction = (f"<h2>Friction modifier: squeal per friction state</h2>{html_table(tables['friction'])}"
                "<p class=\"meta\">Friction states compared, not before and after an applicator's start (the "
                "bag holds no such event). The cut is the model's, on the squealing passes of each state; "
                "Eadie &amp; Santoro (2006) measured 6.3-22.8 dB(A) at transit curves.</p>"
                if tables["friction"] else "")
    if tables["applicator"]:
        friction = (f"<h2>Friction modifier: squeal before and after the applicator's start</h2>"
                    f"{html_table(tables['applicator'])}<p class=\"meta\">Every pass before the applicator's first "
                    "start against every pass after it (to its next stop), whatever friction state each records. "
                    "Levels are energy means over all passes of a side (a quiet pass at the model's background) "
                    "and over its loudest passes, as many as squealed before the start; Eadie &amp; Santoro "
                    "(2006) measured cuts of 6.3-22.8 dB(A) at transit curves.</p>")
    measured = (f"<h2>Measured noise: wheel-defect suspects (repeat offenders)</h2>"
                f"{html_table(tables['offenders'], 25)}{fig('measured')}" if "measured" in figs else "")
    if tables["squeal_angles"]:
        measured += (f"<h2>Measured squeal against the model, by angle of attack</h2>"
                     f"{html_table(tables['squeal_angles'])}<h2>Repeat squealers</h2>"
                     f"{html_table(tables['repeat_squealers'], 25)}")
    if tables["squeal_fits"]:
        measured += (f"<h2>The squeal model fitted to the measured squeal</h2>{html_table(tables['squeal_fits'])}"
                     "<p class=\"meta\">Each friction state's latest fit (squeal.fit_days windows); the passes "
                     "after it are predicted on its P50 curve.</p>" + fig("squeal_fits"))
    advice = (f"<h2>Speed advice per class</h2>{html_table(tables['advice'])}<p class=\"meta\">Shares of each "
              "class's trains per speed band at its recent mean speed, cutting the peak corrugation growth "
              "without raising the mean noise by more than the limit or the squealing share.</p>"
              if tables["advice"] else "")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>rail_monitor report: {e(meta['site_id'])}</title>
<style>{PAGE_CSS}</style></head><body>
<h1>rail_monitor report: {e(meta['site_id'])}</h1>
<p class="meta">Generated {e(meta['generated_local'])} ({e(meta['generated_utc'])}) by rail_monitor
{e(meta['software_version'])} from {e(printable(meta['bag']))}. Times are local ({e(meta['time_zone'])});
speeds in km/h.
Also as <a href="report.pdf">PDF</a>; every squealing pass in <a href="squealing_trains.csv">squealing_trains.csv</a>;
the numbers in <a href="summary.json">summary.json</a>.</p>
<h2>Headline</h2><ul class="head">{lines}</ul>
<h2>Per vehicle class</h2>{html_table(tables['classes'])}
<h2>Noise against the limit</h2>{html_table(tables['noise'])}
<h2>Grinding outlook per band</h2>{html_table(tables['outlook'], 8)}
<p class="meta">Dates at the recent traffic; the range is the spread of weekly traffic only (the growth
coefficient's own uncertainty is not included). The band the model forecasts first uses its full
forecast, the others the fastest growth rate of the band.</p>
{fig('timeline')}
{friction}
<h2>Squealing trains (loudest first)</h2>{html_table(tables['squealers'], 25)}
{measured}
{_listen_html(list(listen))}
<h1>Appendix for engineers</h1>
{fig('corrugation')}{fig('noise')}{fig('squeal')}{advice}{fig('speeds')}
<h2>Alerts (raise and clear events)</h2>{html_table(alerts)}
<h2>Site parameters</h2><p class="meta">As in the site file{': ' + e(meta['site_file']) if meta['site_file'] else ''};
every other parameter at its default.</p>{html_table(params)}
</body></html>
"""
