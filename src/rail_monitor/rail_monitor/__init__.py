"""rail_monitor: wayside prediction of rail corrugation growth, rolling noise and wheel squeal.

Pure physics lives in :mod:`rail_monitor.models` (no rclpy); bag and CSV input/output in
:mod:`rail_monitor.bagio`; the thin ROS 2 nodes in :mod:`rail_monitor.nodes`.
"""

__version__ = "0.1.0"
