"""rail_monitor: wayside prediction of rail corrugation growth, rolling noise and wheel squeal.

Pure physics lives in :mod:`rail_monitor.models` (no rclpy); bag and CSV input/output in
:mod:`rail_monitor.bagio`; the thin ROS 2 nodes in :mod:`rail_monitor.nodes`.

Importing the package limits the maths libraries (OpenBLAS, OpenMP, MKL) to one thread unless the
environment already says otherwise: the arrays here are small, and a pool of threads per process
on a small shared box (a wayside computer, six graph processes on two cores) stalls everything
(a track receptance took 25-50 s instead of 2.6 s on a loaded 2-core machine). This must run
before numpy is first imported, which every entry point does through this package.
"""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

def _version() -> str:
    """The installed package's version (set in package.xml, the one place)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("rail_monitor")
    except PackageNotFoundError:  # imported from a source tree that colcon has not installed
        return "unknown"


__version__ = _version()
