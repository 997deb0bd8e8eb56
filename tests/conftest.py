"""Shared fixtures. Tests run inside the workspace environment (ros2_ws/run test)."""

from __future__ import annotations

import atexit
import contextlib
import itertools
import os
import shutil
import subprocess
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from rosbags.interfaces import Nodetype

TOP = Path(__file__).resolve().parents[1]
SAMPLE = TOP / "bags" / "sample"
EXAMPLE_CSV = TOP / "bags" / "example_passes.csv"
SITE_FILE = TOP / "src" / "rail_monitor" / "config" / "curve_250.yaml"


_INTS = {"int8": 7, "uint8": 8, "byte": 8, "char": 8, "int16": 15, "uint16": 16, "int32": 31, "uint32": 32,
         "int64": 63, "uint64": 64}


def _random_value(rng: np.random.Generator, node) -> object:
    kind, detail = node
    if kind == Nodetype.BASE:
        name = detail[0]
        if name == "string":
            return "".join(rng.choice(list("ab_Zé€ 0")) for _ in range(int(rng.integers(0, 12))))
        if name == "bool":
            return bool(rng.integers(2))
        if name.startswith("float"):
            return float(np.float32(rng.normal(0, 1e3))) if name == "float32" else float(rng.normal(0, 1e6))
        bits = _INTS[name]
        lo = -(2 ** bits) if name.startswith("int") else 0
        return int(rng.integers(lo, 2 ** bits, dtype=np.uint64 if bits == 64 and lo == 0 else np.int64))
    if kind == Nodetype.NAME:
        return random_fields(rng, detail)
    length = detail[1] if kind == Nodetype.ARRAY else int(rng.integers(0, 5))
    return [_random_value(rng, detail[0]) for _ in range(length)]


def random_fields(rng: np.random.Generator, typename: str) -> dict:
    """Random plain fields of every field of a message type (codec.cdr's input): random string
    lengths, sequence lengths and values, over each type's whole range."""
    from rail_monitor.codec.typestore import typestore

    return {name: _random_value(rng, node) for name, node in typestore().fielddefs[typename][1]}


def _claim_domain_group() -> tuple[int, object]:
    """One of 11 groups of DDS domains for this test run, held (an exclusive lock) until it ends:
    two runs on the machine never share a domain. Group g owns domains 1 + 20 g ... 20 + 20 g for
    tests and 221 + g for module-wide graphs."""
    import fcntl
    import tempfile

    folder = Path(tempfile.gettempdir()) / "rail_monitor_test_domains"
    folder.mkdir(exist_ok=True)
    for group in range(11):
        f = open(folder / f"group_{group}.lock", "w")  # noqa: SIM115 (held open for the run)
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return group, f
        except OSError:
            f.close()
    raise RuntimeError("all 11 groups of test DDS domains are taken by other test runs")


DOMAIN_GROUP, _DOMAIN_LOCK = _claim_domain_group()
GRAPH_DOMAIN = 221 + DOMAIN_GROUP  # for module-scoped fixtures that outlive a test
_DOMAINS = itertools.count()
# Discovery stays on this machine: a test graph never meets another host's, nor theirs ours.
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ["ROS_DOMAIN_ID"] = str(GRAPH_DOMAIN)
# The disk cache of site tables (rail_monitor.core.cache) of this run only, shared by its processes:
# the tests never read a cache another version wrote, nor leave one in the user's home.
os.environ["RAIL_MONITOR_CACHE"] = tempfile.mkdtemp(prefix="rail_monitor_test_cache_")
atexit.register(shutil.rmtree, os.environ["RAIL_MONITOR_CACHE"], ignore_errors=True)  # it made the folder


@pytest.fixture(autouse=True)
def _isolated_dds(monkeypatch: pytest.MonkeyPatch) -> None:
    # A DDS domain of its own per test: endpoints of an earlier test (which discovery may still
    # list for a moment) and other test runs on the machine never join this test's graph.
    monkeypatch.setenv("ROS_DOMAIN_ID", str(1 + 20 * DOMAIN_GROUP + next(_DOMAINS) % 20))
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")


@pytest.fixture()
def site():
    from rail_monitor.site_file import load_site

    return load_site(SITE_FILE)


@pytest.fixture()
def site_values() -> dict:
    from rail_monitor.site_file import load_parameter_file

    return load_parameter_file(SITE_FILE)


@pytest.fixture(scope="session")
def sample_passes():
    from rail_monitor.bagio.reader import read_bag_passes

    return read_bag_passes(SAMPLE)


@pytest.fixture()
def ros_context() -> Iterator[object]:
    """A fresh rclpy Context per test, shut down afterwards."""
    import rclpy
    from rclpy.context import Context

    ctx = Context()
    rclpy.init(context=ctx, domain_id=int(os.environ["ROS_DOMAIN_ID"]))
    try:
        yield ctx
    finally:
        rclpy.try_shutdown(context=ctx)


@pytest.fixture()
def tmpfs(tmp_path: Path):
    """A factory of tmpfs mounts of a given size [bytes] under tmp_path (skips without CAP_SYS_ADMIN);
    unmounted after the test."""
    mounted: list[Path] = []

    def mount(size: int) -> Path:
        disk = tmp_path / f"disk{len(mounted)}"
        disk.mkdir()
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(disk)], capture_output=True,
                           text=True)
        if r.returncode:
            pytest.skip(f"cannot mount a tmpfs here (needs CAP_SYS_ADMIN): {r.stderr.strip()}")
        mounted.append(disk)
        return disk

    yield mount
    for disk in mounted:
        subprocess.run(["umount", "-l", str(disk)], capture_output=True)


def executable(name: str) -> str:
    """Resolve an executable the way `ros2 run rail_monitor <name>` does: ament index -> prefix/lib/pkg."""
    from ament_index_python.packages import get_package_prefix, get_resource

    get_resource("packages", "rail_monitor")  # raises LookupError if the package is not registered
    path = Path(get_package_prefix("rail_monitor")) / "lib" / "rail_monitor" / name
    assert path.is_file() and os.access(path, os.X_OK), path
    return str(path)


def run_cmd(*args: str, timeout: float = 120.0, **kw) -> subprocess.CompletedProcess:
    """Run a workspace executable (PATH set by ros2_ws/run) and capture its output."""
    env = {**os.environ, **kw.pop("env", {})}
    cwd = kw.pop("cwd", TOP)
    return subprocess.run(list(args), capture_output=True, text=True, timeout=timeout, env=env, cwd=cwd, **kw)



@contextlib.contextmanager
def spinning(ctx, *nodes) -> Iterator[object]:
    """Spin nodes on a SingleThreadedExecutor in a background thread; shut it down on exit."""
    from rclpy.executors import SingleThreadedExecutor

    from rail_monitor.nodes.process import shut_down, spin_guarded

    ex = SingleThreadedExecutor(context=ctx)
    for node in nodes:
        ex.add_node(node)
    done = threading.Event()
    # As every executable spins: one callback's exception is counted and the executor goes on.
    spinner = threading.Thread(target=spin_guarded, args=(ex, lambda: not done.is_set()), daemon=True)
    spinner.start()
    try:
        yield ex
    finally:
        done.set()
        shut_down(ex, 2.0)
        spinner.join(timeout=5)


def wait_until(condition, timeout_s: float = 10.0, period_s: float = 0.01) -> bool:
    """Poll condition() until it is true or timeout_s passes; return its last value."""
    deadline = time.monotonic() + timeout_s
    while not condition() and time.monotonic() < deadline:
        time.sleep(period_s)
    return bool(condition())


# -- the reliability table (issue 8) ------------------------------------------------------------
_TALLY: list[dict[str, object]] = []
TALLY_FILE = TOP / "out" / "reliability.md"


@pytest.fixture()
def tally(request: pytest.FixtureRequest):
    """Record what a reliability test tried, what held and how many messages were lost; the
    session writes the rows to out/reliability.md (the README's table comes from there)."""

    def add(area: str, tried: str, held: str, lost: int | str) -> None:
        _TALLY.append({"area": area, "tried": tried, "held": held, "lost": lost, "test": request.node.name})

    return add


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if not _TALLY:
        return
    TALLY_FILE.parent.mkdir(exist_ok=True)
    lines = ["| area | tried | what holds | messages lost | test |", "|---|---|---|---|---|"]
    lines += [f"| {r['area']} | {r['tried']} | {r['held']} | {r['lost']} | `{r['test']}` |" for r in _TALLY]
    TALLY_FILE.write_text("\n".join(lines) + "\n")


def band_noise_tolerance_db(bands, tp_s: float) -> np.ndarray:
    """How far the pass-by processor may read a band of synthesised noise from what its filter passes
    of the noise (band_readings_db) [dB]: 0.1 dB, plus two standard deviations of the power of Gaussian
    noise of the band's width B over Tp (4.34 / sqrt(B Tp) dB)."""
    from rail_monitor.models.iec61260 import band_edges

    lo, hi = band_edges(bands)
    return 0.1 + 2 * 4.34 / np.sqrt((hi - lo) * tp_s)


def band_readings_db(level_db, bands) -> np.ndarray:
    """What the processor's band filters pass of noise of flat density within each band at these
    levels [dB]: sum over bands b' of P_b' times the mean of |H_b|^2 over b' (numerical integration;
    the filters' effective bandwidth and their skirts over a stepped spectrum)."""
    from rail_monitor.models.iec61260 import band_edges, band_power_response

    lo, hi = band_edges(bands)
    p = 10 ** (np.asarray(level_db, float) / 10)
    coupling = np.empty((len(bands), len(bands)))
    for j, (a, b) in enumerate(zip(lo, hi, strict=True)):
        f = np.linspace(a, b, 2001)
        coupling[:, j] = np.trapezoid(band_power_response(f, np.asarray(bands)), f, axis=-1) / (b - a)
    return 10 * np.log10(coupling @ p)


def write_pass_audio(folder: Path, stamp_ns: int, train_id: str, lead_s: float = 1.0, fs_hz: float = 32_000.0,
                     **pass_kw):
    """A predicted pass of the shipped site (rail_monitor.whatif.audio.pass_audio with pass_kw) written
    where a station's recorder leaves it: folder/<audio_name>, float WAV in pascals, lead_s before
    the pass. Returns the PassAudio."""
    from scipy.io import wavfile

    from rail_monitor.site_file import load_parameter_file
    from rail_monitor.station.pass_audio import audio_name
    from rail_monitor.whatif.audio import pass_audio

    a = pass_audio(load_parameter_file(SITE_FILE), fs_hz=fs_hz, margin_s=lead_s, **pass_kw)
    folder.mkdir(parents=True, exist_ok=True)
    wavfile.write(folder / audio_name(stamp_ns, train_id), int(fs_hz), a.pressure_pa.astype(np.float32))
    return a


def same_record(a, b) -> bool:
    """Two dataclass records equal field by field, arrays element by element, NaN equal to NaN."""
    import dataclasses

    def equal(x, y) -> bool:
        x, y = np.asarray(x), np.asarray(y)
        return np.array_equal(x, y, equal_nan=x.dtype.kind == "f" and y.dtype.kind == "f")

    return all(equal(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))


def node_parameters(values: dict, **extra) -> list:
    """rclpy Parameters of a node for the site's flat values (the simulator's aside) and extra ones."""
    from rclpy.parameter import Parameter

    return [Parameter(k, value=v) for k, v in {**values, **extra}.items() if not k.startswith("simulator.")]


def write_two_sites(folder: Path, days: float) -> None:
    """Two sites in folder: curve_250.yaml with the example history a.csv, and curve_400.yaml (radius
    400 m) with b.csv, simulated over days."""
    from rail_monitor.cli import main
    from rail_monitor.cli.site import edited_site_text

    text, _ = edited_site_text(SITE_FILE.read_text(), ["site_id=curve_400", "curve_radius_m=400.0",
                                                       f"simulator.days={days}", "simulator.seed=7"])
    (folder / "curve_400.yaml").write_text(text)
    (folder / "curve_250.yaml").write_text(SITE_FILE.read_text())
    (folder / "a.csv").write_text(EXAMPLE_CSV.read_text())
    assert main(["simulate", "--site", str(folder / "curve_400.yaml"), "--csv", str(folder / "b.csv")]) == 0
