"""Benchmarks (python -m bench). Importing the package sets the process environment every benchmark
and its child processes share: a DDS domain of this run's own, discovery on this machine only,
and one thread for the maths library (this is a small shared box: see the README)."""

import os

os.environ.setdefault("ROS_DOMAIN_ID", str(150 + os.getpid() % 50))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
