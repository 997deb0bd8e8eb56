"""Pass-by processing speed: a calibrated 10 s record at 48 kHz through the ISO 3095 processor
(A weighting, F time weighting, 24 one-third-octave bands, tones), as a multiple of real time on
one core (issue 54's target: at least 50x per channel).

Run: ros2_ws/run python -m bench.audio [--seconds 10]
"""

from __future__ import annotations

import numpy as np

import bench  # noqa: F401  (one maths thread)
from bench.timing import best_of, header, parser
from rail_monitor.models.iso3095 import passby_levels

FS = 48_000


def costs(seconds: float = 10.0) -> dict[str, float]:
    """Seconds to process a record of that many seconds (best of 5), and the multiple of real time."""
    rng = np.random.default_rng(54)
    t = np.arange(round(seconds * FS)) / FS
    p = rng.normal(0.0, 0.2, len(t)) + 0.5 * np.sin(2 * np.pi * 800.0 * t)  # rolling noise and a squeal-like tone
    s = best_of(lambda: passby_levels(p, FS, 0.2 * seconds, 0.8 * seconds), 5)
    return {"seconds": s, "real_time_x": seconds / s}


def main() -> None:
    ap = parser(__doc__)
    ap.add_argument("--seconds", type=float, default=10.0)
    ns = ap.parse_args()
    header("audio")
    c = costs(ns.seconds)
    print(f"{ns.seconds:g} s at 48 kHz processed in {c['seconds'] * 1e3:.0f} ms: {c['real_time_x']:.0f}x real time")


if __name__ == "__main__":
    main()
