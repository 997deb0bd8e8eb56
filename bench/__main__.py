"""All benchmarks in one run, printed as one table (and written to out/bench.md).

Run: ros2_ws/run python -m bench [--quick]

Figures are measured side by side in this run only: compare ratios within a run, not absolute
times across machines. Sections: the graph against its rclpy ceiling (the no-op graph of
bench.bare_graph); the live graph's start-up, idle CPU, CPU and latency (bench.live); batch mode at
1e4, 1e5 and 1e6 passes; a busy site's year live and in batch;
per-model cost per pass; the recorder against the bare mcap writer; peak memory against passes
(the graph, the recorder, the streamed batch, and export in parts against read whole);
many sites on a local Dask cluster of 1 and 2 workers; a grinding programme for 500 sites over 5
years (bench.plan); where a live pass's time goes in the site engine (bench.engine_pass).
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from bench import audio as baudio
from bench import batch as bb
from bench import corrugation as bc
from bench import engine_pass as bep
from bench import graph as bg
from bench import live as blive
from bench import noise as bn
from bench import plan as bplan
from bench import recorder as br
from bench import sites as bsites
from bench import squeal as bs
from bench import station as bstation
from bench.timing import first_touch_s
from rail_monitor.bagio.passes_bag import write_passes_bag
from rail_monitor.bagio.reader import read_passes
from rail_monitor.batch.bag import run_to_bag, write_bag
from rail_monitor.batch.run import run_models
from rail_monitor.site_file import load_parameter_file

Row = tuple[str, str, str]  # what, figure, note


def machine() -> str:
    mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return (f"{platform.node()}: {os.cpu_count()} cores ({platform.processor() or platform.machine()}), "
            f"{mem:.0f} GiB, Python {platform.python_version()}, numpy {np.__version__}, "
            f"{datetime.now(UTC):%Y-%m-%d}")


def rate(passes: float, seconds: float) -> str:
    return f"{passes / seconds:,.0f} passes/s"


def graph_rows(source: str, site: str, keep: Path, repeat: int) -> list[Row]:
    bare1 = bg.in_process("bare", source, site, max_batch=1)
    pairs = bg.alternating(source, site, repeat, output=str(keep))
    bare, real = (min(runs, key=lambda x: x["replay_s"]) for runs in zip(*pairs, strict=True))
    ratios = bg.ceiling_ratios(pairs)
    n = real["passes"]
    return [
        (f"no-op graph, one message per callback (rclpy's default), {n} passes", rate(n, bare1["replay_s"]), ""),
        (f"no-op graph, queued messages taken at once (as the real graph), {n} passes", rate(n, bare["replay_s"]),
         f"the ceiling; the fastest of {repeat} runs"),
        (f"real graph (wayside_monitor), {n} passes", rate(n, real["replay_s"]),
         f"the fastest of {repeat} runs, each after a no-op run; set-up {real['setup_s']:.1f} s apart"),
        ("real / ceiling", f"{np.median(ratios):.2f}",
         f"median of the {repeat} pairs ({', '.join(f'{x:.2f}' for x in ratios)}); against rclpy's default "
         f"dispatch: {bare1['replay_s'] / real['replay_s']:.2f}"),
        *((f"no-op replay + the site engine alone {what}", f"{bound:.2f}",
           f"of the ceiling: engine {t['engine_s']:.2f} s, its outputs' CDR {t['outputs_s']:.2f} s, no DDS "
           "(the best a one-process graph could reach)")
          for what, t, bound in bg.engine_bounds(source, site, [b for b, _ in pairs])),
    ]


def batch_rows(values: dict, site: str, sizes: list[int]) -> list[Row]:
    fresh, again = first_touch_s()
    rows: list[Row] = [("filling 256 MB new to this process", f"{fresh:.2f} s",
                        f"{again:.2f} s again once freed: memory new to the machine costs more the first time "
                        "(a first batch run pays it)"),
                       ("batch set-up (site tables, compiled kernels; once per process)",
                        f"{bb.set_up_s(values):.2f} s", "")]
    for size in sizes:
        n, t, _ = bb.timed(values, size)
        rows.append((f"batch, {n:,} simulated passes", rate(n, t),
                     f"{t:.1f} s; peak RSS so far {bb.peak_rss_mb():,.0f} MB"))
    n, t = bb.on_cores_in_subprocess(site, sizes[1], 1)
    rows.append((f"batch, {n:,} simulated passes, one core", rate(n, t), f"{t:.1f} s; a process held to one CPU"))
    return rows


def year_rows(values: dict, site: str, passes: int, tmp: Path) -> tuple[list[Row], list[Row]]:
    """A busy site's year live and in batch; and the graph's peak memory at a tenth of it and all of it."""
    rows: list[Row] = []
    memory: list[Row] = []
    table = bb.busy_history(values, passes)
    for frac, name in ((0.1, "tenth"), (1.0, "year")):
        part = table.take(slice(0, int(len(table) * frac)))
        bag = tmp / f"busy_{name}"
        write_passes_bag(part, bag, "")
        live = bg.in_process("real", str(bag), site)
        memory.append((f"graph peak RSS, {len(part):,} passes", f"{live['peak_rss_mb']:,.0f} MB",
                       "wayside_monitor, recorder in the process"))
        rec = bg.recorder_process(str(bag))
        memory.append((f"recorder peak RSS, {rec['recorded']:,} passes", f"{rec['peak_rss_mb']:,.0f} MB",
                       "mcap_recorder process fed by pass_replayer over DDS at "
                       f"{rate(rec['recorded'], rec['replay_s'])}"))
        if frac == 1.0:
            t = time.perf_counter()
            run_models(part, values)
            t_batch = time.perf_counter() - t
            rows += [(f"busy year live ({len(part):,} passes)", f"{live['replay_s'] + live['setup_s']:.0f} s",
                      f"{rate(len(part), live['replay_s'])} after {live['setup_s']:.1f} s set-up"),
                     (f"busy year in batch ({len(part):,} passes)", f"{t_batch:.1f} s", rate(len(part), t_batch))]
    return rows, memory


def streamed_rows(site: str, sizes: list[int]) -> list[Row]:
    """Peak memory of the streamed batch (as rail-monitor batch runs a bag) against history length,
    each size in a fresh process."""
    rows: list[Row] = []
    for size in sizes:
        n, t, mb = bb.streamed_in_subprocess(site, size)
        rows.append((f"batch streamed to a bag, {n:,} passes", f"{mb:,.0f} MB",
                     f"peak RSS of the process; {rate(n, t)} with the recording"))
    return rows


def export_rows(values: dict, site: str, passes: int, tmp: Path) -> list[Row]:
    """rail-monitor export of a batch bag, in parts and read whole, each in a fresh process: peak memory."""
    bag = tmp / "export_bag"
    run_to_bag(bb.busy_chunks(values, passes, 5_000), values, bag, "site")
    rows: list[Row] = []
    for chunk in (5_000, 0):
        out = tmp / f"export_{chunk}"
        code = ("import sys, time; from rail_monitor.cli import main; from bench.timing import peak_rss_mb; "
                "t = time.perf_counter(); rc = main(sys.argv[1:]); print(rc, time.perf_counter() - t, peak_rss_mb())")
        done = subprocess.run([sys.executable, "-c", code, "export", str(bag), "--format", "parquet", "--chunk",
                               str(chunk), "--site", site, "--output", str(out)],
                              capture_output=True, text=True, check=True)
        rc, t, mb = done.stdout.split()[-3:]
        assert rc == "0", done.stdout
        how = f"in parts of {chunk:,} passes" if chunk else "read whole"
        rows.append((f"export to Parquet, {passes:,} passes, {how}", f"{float(mb):,.0f} MB",
                     f"peak RSS of the process; {float(t):.1f} s"))
    return rows


def model_rows(site: str) -> list[Row]:
    sq = bs.costs(site)
    co = bc.costs(site)
    no = bn.costs(site)
    us = 1e6
    rows = [("squeal, closed form (one case)", f"{sq['closed_form'] * us:.0f} us", ""),
            ("squeal, time integration (one case)", f"{sq['ode'] * 1e3:.0f} ms",
             f"{sq['ode'] / sq['closed_form']:,.0f} x the closed form"),
            ("squeal prediction per pass (contact, k3, limit cycle, levels)", f"{sq['pass_single'] * us:.0f} us",
             f"{sq['pass_batch'] * us:.1f} us in a batch"),
            ("corrugation update + forecast per pass", f"{co['pass_single'] * us:.0f} us",
             f"{co['pass_batch'] * us:.1f} us in a batch")]
    rows += [(f"rolling noise, {name}, per pass with a corrugation state", f"{c['pass_single'] * us:.0f} us",
              f"{c['pass_batch'] * us:.1f} us in a batch") for name, c in no.items()]
    au = baudio.costs(10.0)
    rows.append(("pass-by audio, 10 s at 48 kHz (ISO 3095 levels, bands, tones)", f"{au['seconds'] * 1e3:.0f} ms",
                 f"{au['real_time_x']:.0f}x real time on one core"))
    return rows


def recorder_rows(values: dict, source: str, tmp: Path) -> list[Row]:
    bag = tmp / "batch_bag"
    write_bag(run_models(read_passes(source), values), bag, "curve_250")
    c = br.compare(bag)
    return [(f"recorder write ({c['messages']:,} messages, {c['mb']:.0f} MB CDR, zstd)",
             f"{c['recorder_per_s']:,.0f} messages/s", f"{c['recorder_per_s'] / c['bare_per_s']:.2f} x bare mcap"),
            ("bare mcap Writer, same messages", f"{c['bare_per_s']:,.0f} messages/s", "")]


def table(sections: list[tuple[str, list[Row]]]) -> str:
    lines = ["| benchmark | figure | note |", "| --- | ---: | --- |"]
    for name, rows in sections:
        lines.append(f"| **{name}** | | |")
        lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--site", default="src/rail_monitor/config/curve_250.yaml")
    ap.add_argument("--source", default="bags/sample", help="history for the graph and recorder comparisons")
    ap.add_argument("--quick", action="store_true", help="small sizes (a check that the harness runs)")
    ap.add_argument("--out", default="out/bench.md")
    ns = ap.parse_args()
    values = load_parameter_file(ns.site)
    sizes = [1000, 3000] if ns.quick else [10_000, 100_000, 1_000_000]
    year = 2000 if ns.quick else bb.BUSY_YEAR
    sections: list[tuple[str, list[Row]]] = []
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        source = ns.source
        if ns.quick:
            source = str(tmp / "short")
            write_passes_bag(read_passes(ns.source).take(slice(0, 600)), Path(source), "")
        live_bag = tmp / "live"
        graph = graph_rows(source, ns.site, live_bag, 1 if ns.quick else 3)
        sections.append(("graph against its rclpy ceiling", graph))
        sections.append(("live graph as a site runs it", blive.rows(ns.site, ns.source, [1.0, 20.0] if ns.quick
                                                                     else [1.0, 100.0], 2.0 if ns.quick else 10.0,
                                                                     2.0 if ns.quick else 10.0)))
        sections.append(("a live pass through the site engine", bep.rows(ns.site, ns.source, 2.0 if ns.quick else 28.0,
                                                                           60 if ns.quick else 300)))
        eq = bb.live_equality(str(live_bag), values)
        sections.append(("batch", [*batch_rows(values, ns.site, sizes), (
            "batch against the live graph (same passes)", f"{eq['corrugation_rel']:.1e}",
            f"largest relative difference of corrugation; levels {max(eq['noise_db'], eq['squeal_db']):.1e} dB; "
            f"state count {eq['states']:+.0f}, alert count {eq['alerts']:+.0f}")]))
        year_r, memory = year_rows(values, ns.site, year, tmp)
        sections.append(("a busy site's year", year_r))
        sections.append(("models, per pass", model_rows(ns.site)))
        st = bstation.costs(ns.site, 5 if ns.quick else 20)
        sections.append(("noise station", [(
            f"noise_station hearing {st['passes']} passes of 10 s at 48 kHz",
            f"{st['per_pass_s'] * 1e3:.0f} ms CPU a pass",
            f"heard {st['heard']}; idle {100 * st['idle_share']:.2f} % of a core; 100 passes an hour "
            f"{100 * st['duty_share']:.2f} % of a core")]))
        sections.append(("recorder", recorder_rows(values, source, tmp)))
        sections.append(("memory against passes", memory + streamed_rows(
            ns.site, [2_000, 6_000] if ns.quick else [100_000, 1_000_000])
            + export_rows(values, ns.site, 2_000 if ns.quick else 100_000, tmp)))
        sections.append(("many sites on a local Dask cluster", bsites.rows(values, ns.site, 2 if ns.quick else 4,
                                                                           1000 if ns.quick else 20_000)))
        sections.append(("a grinding programme for a network", bplan.rows(50 if ns.quick else 500, 5)))
    text = f"Machine: {machine()}\n\n{table(sections)}\n"
    print(text)
    Path(ns.out).parent.mkdir(parents=True, exist_ok=True)
    Path(ns.out).write_text(text)


if __name__ == "__main__":
    main()
