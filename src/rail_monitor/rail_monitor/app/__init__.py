"""What runs on the models without ROS: batch mode, the run report and its plots, the traffic
simulator. Nothing here imports rclpy or the generated messages (:mod:`rail_monitor.nodes`)."""
