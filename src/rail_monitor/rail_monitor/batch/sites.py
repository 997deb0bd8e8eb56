"""Batch mode over many sites: a manifest of (site file, history) pairs, one task per site on a
Dask cluster, outputs per site.

Sites are independent (each has its own state, traffic and alerts), so a site is the unit of
work: a task reads the site's history, runs the models (rail_monitor.batch.run), records the bag
next to the history (or where the manifest says) with the site file stored in it, and returns a
one-line summary. Dask was chosen over Ray: pure-Python wheels, no daemon of its own, a local
cluster in two lines, and ``dask scheduler`` / ``dask worker`` to spread the same tasks over many
machines. By default a local cluster of one single-threaded worker process per core runs the
tasks; ``scheduler`` connects to a running cluster instead.

The manifest (YAML; paths relative to the manifest's folder)::

    sites:
      - site: curve_250.yaml          # site parameter file
        history: curve_250.csv        # bag folder, .mcap, .db3 or .csv
        output: out/curve_250_batch   # optional; default <history>_batch beside the history

``rail-monitor plan`` reads the same manifest, and also takes ``checkpoint:`` (a live site's
corrugation checkpoint) in place of ``history:``; each task returns the site's grinding outlook.
"""

from __future__ import annotations

import functools
import logging
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

from rail_monitor.bagio.output_folder import beside
from rail_monitor.core.errors import ConfigError, RailMonitorError
from rail_monitor.core.user_file import read_user_text
from rail_monitor.core.yaml_text import load_yaml


# One site of a manifest: its site file, its history (or checkpoint: plan only), and the bag folder to write.
class SiteJob(NamedTuple):
    site: Path
    history: Path | None
    output: Path | None
    checkpoint: Path | None = None


@dataclass(frozen=True)
class SiteResult:
    """What a site's task reports (seconds: its own run; worker: where it ran)."""

    site_id: str
    output: str
    passes: int
    rejected: int
    alert_events: int
    days_to_threshold: float
    seconds: float
    worker: str


def read_manifest(path: str | Path, checkpoints: bool = False) -> list[SiteJob]:
    """The jobs of a manifest (ConfigError with one line naming the entry at fault); checkpoints:
    an entry may give ``checkpoint:`` instead of ``history:`` (plan), and has no output."""
    path = Path(path)
    text = read_user_text(path, "a manifest", error=ConfigError)
    doc = load_yaml(text, f"{path}: cannot read the manifest", ConfigError)
    entries = doc.get("sites") if isinstance(doc, dict) else None
    if not isinstance(entries, list) or not entries:
        raise ConfigError(f"{path}: expected 'sites:' with a list of entries (site:, history:, output:)")
    jobs, outputs = [], set()
    base = path.parent.resolve()  # absolute: a worker on another host has its own working folder
    keys = {"site", "history", "output"} | ({"checkpoint"} if checkpoints else set())
    for i, entry in enumerate(entries):
        where = f"{path}: sites[{i}]"
        sources = {"history", "checkpoint"} & set(entry) if isinstance(entry, dict) else set()
        if not isinstance(entry, dict) or "site" not in entry or len(sources) != 1 or set(entry) - keys:
            raise ConfigError(f"{where}: expected the keys site and " + ("history or checkpoint" if checkpoints else
                                                                         "history (and optionally output)"))
        site, source = base / str(entry["site"]), base / str(entry[next(iter(sources))])
        for p in (site, source):
            if not p.exists():
                raise ConfigError(f"{where}: {p} not found")
        if checkpoints:
            jobs.append(SiteJob(site, source if "history" in entry else None, None,
                                source if "checkpoint" in entry else None))
            continue
        output = base / str(entry["output"]) if entry.get("output") else beside(source, "_batch")
        if output.resolve() in outputs:
            raise ConfigError(f"{where}: output {output} is another site's too")
        outputs.add(output.resolve())
        jobs.append(SiteJob(site, source, output))
    return jobs


def run_site(job: SiteJob) -> SiteResult:
    """One site's batch run, recorded to its output (a task: imports inside, runs on a worker)."""
    from rail_monitor.bagio.site_record import site_record
    from rail_monitor.batch.bag import record_history
    from rail_monitor.site_file import load_parameter_file

    t0 = time.monotonic()
    values = load_parameter_file(job.site)
    if job.output.exists():
        raise RailMonitorError(f"{job.output} exists: remove it or give another output")
    site_id = str(values.get("site_id", ""))
    rec = record_history(job.history, values, job.output, site_id, site=site_record(job.site))
    return SiteResult(site_id, str(job.output), rec.passes, rec.rejected, rec.alert_events, rec.days_to_threshold,
                      time.monotonic() - t0, _worker_name())


def outlook_site(job: SiteJob) -> Any:
    """One site's grinding outlook (economics.outlook.SiteOutlook) from its history, surveys and
    grinding events applied, or from its checkpoint, with the options its economics.options offer
    priced (a task: imports inside, runs on a worker)."""
    return _site_outlooks(job, False)[0]


def outlook_history(job: SiteJob) -> Any:
    """One site's outlook now (as outlook_site) and those its engine made on each survey, grinding
    or indirect observation of its history, with their stamps [ns] (a checkpoint: none)."""
    return _site_outlooks(job, True)


def _site_outlooks(job: SiteJob, made: bool) -> tuple[Any, list[tuple[int, Any]]]:
    from rail_monitor.advice.consequences import Consequences
    from rail_monitor.bagio.reader import read_bag_events, read_passes
    from rail_monitor.core.passes import accepted_passes
    from rail_monitor.corrugation.estimator import CorrugationEstimator
    from rail_monitor.economics.options import configured_outlook
    from rail_monitor.engine import checkpoint
    from rail_monitor.engine.corrugation_site import advance_with_events
    from rail_monitor.engine.site_config import SiteConfig
    from rail_monitor.noise.predict import RollingNoiseModel
    from rail_monitor.site_file import load_parameter_file

    cfg = SiteConfig.from_values(load_parameter_file(job.site))
    est = CorrugationEstimator(cfg.site, cfg.corrugation)
    consequences = functools.cache(lambda: Consequences(cfg.site, RollingNoiseModel(cfg.site, cfg.noise), cfg.squeal))

    def outlook() -> Any:
        return configured_outlook(est, cfg.economics, consequences)

    history: list[tuple[int, Any]] = []
    if job.checkpoint is not None:
        checkpoint.load(est, job.checkpoint)
    else:
        passes = read_passes(job.history)
        step = advance_with_events(est, accepted_passes(passes, cfg.site), read_bag_events(job.history),
                                   outlook if made else None)
        history = [(e.stamp_ns, o) for e, o in step.outlooks]
    if not est.total_pass_count:
        raise RailMonitorError(f"{job.checkpoint or job.history}: no valid pass of site {cfg.site.site_id}")
    return outlook(), history


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return str(get_worker().address)
    except (ImportError, ValueError):
        return f"pid {os.getpid()}"


def run_sites(jobs: list[SiteJob], workers: int = 0, scheduler: str = "",
              task: Callable[[SiteJob], Any] = run_site) -> list[Any]:
    """task (run_site, or outlook_site) of every job as a Dask task, results in the manifest's
    order. workers: processes of the local cluster (0: one per core); scheduler: the address of a
    running cluster (then workers is not used). A failed site is a RailMonitorError naming it,
    after the others have finished."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        client, cluster = Client(scheduler), None
    else:
        n = workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=logging.WARNING)
        client = Client(cluster)
    try:
        futures = [client.submit(task, job, pure=False, key=f"site-{i}-{job.site.stem}")
                   for i, job in enumerate(jobs)]
        results, failures = [], []
        for job, fut in zip(jobs, futures, strict=True):
            try:
                results.append(fut.result())
            except RailMonitorError as exc:
                failures.append(f"{job.site.name} ({(job.history or job.checkpoint).name}): {exc}")
        if failures:
            raise RailMonitorError(f"{len(failures)} of {len(jobs)} sites failed: " + "; ".join(failures))
        return results
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
