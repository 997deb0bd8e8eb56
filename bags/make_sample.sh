#!/usr/bin/env bash
# Regenerate the bundled sample history bit for bit (seeded simulator, pinned numpy/scipy):
#   bags/sample/            90 days at the 250 m curve of config/curve_250.yaml (rosbag2 MCAP)
#   bags/example_passes.csv the first 2 days of the same site as a detector-style CSV
# Run from the repository top: bash bags/make_sample.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
ros2_ws/run rail-monitor simulate --out bags/sample --force
ros2_ws/run rail-monitor simulate --days 2 --csv bags/example_passes.csv
