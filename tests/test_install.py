"""The ROS-free core installed on its own, as a noise engineer without ROS 2 would install it: a plain
venv, `pip install ./src/rail_monitor`, and the verbs that need no graph (simulate, batch, report,
export, predict, info), with no ROS 2 package importable there."""

from __future__ import annotations

import os
import shutil
import subprocess
import venv

import pytest

from conftest import TOP


@pytest.fixture(scope="module")
def plain(tmp_path_factory):
    """A venv with nothing but the package and its declared dependencies (from the pip cache or
    the package registry), and a clean environment to run it in (no ROS 2 paths)."""
    root = tmp_path_factory.mktemp("plain")
    # The repository's parts the install reads (pip builds in the source folder: in a copy, the
    # working tree gets no build folder), laid out as in the repository.
    tree = root / "tree"
    skip = shutil.ignore_patterns("build", "*.egg-info", "__pycache__")
    shutil.copytree(TOP / "src" / "rail_monitor", tree / "src" / "rail_monitor", symlinks=True, ignore=skip)
    shutil.copytree(TOP / "src" / "rail_msgs", tree / "src" / "rail_msgs", ignore=skip)
    (tree / "ros2_ws").mkdir()
    shutil.copy(TOP / "ros2_ws" / "requirements.txt", tree / "ros2_ws")
    venv.create(root / "venv", with_pip=True)
    bin_dir = root / "venv" / "bin"
    pip = subprocess.run([str(bin_dir / "python"), "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                          str(tree / "src" / "rail_monitor")], capture_output=True, text=True, timeout=900)
    assert pip.returncode == 0, pip.stderr[-3000:]
    env = {"HOME": os.environ.get("HOME", str(root)), "PATH": f"{bin_dir}:/usr/bin:/bin",
           "OPENBLAS_NUM_THREADS": "1", "NUMBA_NUM_THREADS": "1", "LANG": "C.UTF-8"}
    return root, bin_dir, env


def _run(plain, *args: str) -> subprocess.CompletedProcess:
    """rail-monitor of the plain venv in its clean environment (nothing of this one's passed on)."""
    root, bin_dir, env = plain
    return subprocess.run([str(bin_dir / "rail-monitor"), *args], capture_output=True, text=True, cwd=root, env=env,
                          timeout=600)


def test_no_ros_is_there(plain):
    _, bin_dir, env = plain
    r = subprocess.run([str(bin_dir / "python"), "-c", "import rail_monitor, rclpy"], capture_output=True, text=True,
                       env=env)
    assert r.returncode != 0 and "No module named 'rclpy'" in r.stderr
    assert str(TOP) not in subprocess.run([str(bin_dir / "python"), "-c", "import rail_monitor; print(rail_monitor"
                                           ".__file__)"], capture_output=True, text=True, env=env).stdout


def test_simulate_batch_report_export_predict_without_ros(plain):
    root = plain[0]
    r = _run(plain, "simulate", "--days", "10", "--out", "history", "--csv", "history.csv")
    assert r.returncode == 0, r.stderr[-2000:]
    r = _run(plain, "batch", "history")
    assert r.returncode == 0, r.stderr[-2000:]
    assert "through the models" in r.stdout + r.stderr
    assert (root / "history_batch_report" / "index.html").is_file()
    r = _run(plain, "export", "history_batch", "--format", "csv")
    assert r.returncode == 0, r.stderr[-2000:]
    assert (root / "history_batch_export" / "passes.csv").stat().st_size > 0
    for what in ("noise", "squeal", "corrugation"):
        r = _run(plain, "predict", what)
        assert r.returncode == 0, (what, r.stderr[-2000:])
    r = _run(plain, "info", "history_batch")
    assert r.returncode == 0 and "passes:" in r.stdout, r.stderr[-2000:]


def test_a_bag_written_without_ros_reads_as_the_workspace_reads_it(plain):
    """The bag of the plain install, read here (where ROS 2 is installed) by the workspace's reader:
    every pass of the CSV written beside it, field for field."""
    root = plain[0]
    if not (root / "history").exists():
        pytest.skip("needs the simulate run of the test before")
    from rail_monitor.bagio.csv_io import read_csv
    from rail_monitor.bagio.reader import read_passes

    bag, csv = read_passes(root / "history"), read_csv(root / "history.csv")
    assert len(bag) == len(csv) > 0
    for name in ("stamp_ns", "speed_mps", "angle_of_attack_rad", "friction_state"):
        assert (getattr(bag, name) == getattr(csv, name)).all(), name
