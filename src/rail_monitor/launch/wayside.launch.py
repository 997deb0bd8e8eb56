"""Launch the wayside graph as separate processes on a full ROS 2 Jazzy install.

    ros2 launch rail_monitor wayside.launch.py source:=/path/to/history output:=/path/to/bag

Every node reads the site file and runs under the site's namespace on pass time (/clock).
On a machine without ros2launch, start the same executables by hand (see the README).
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description() -> LaunchDescription:
    default_site = os.path.join(get_package_share_directory("rail_monitor"), "config", "curve_250.yaml")
    site = LaunchConfiguration("site")
    ns = LaunchConfiguration("namespace")
    common = {"use_sim_time": True}
    return LaunchDescription([
        DeclareLaunchArgument("site", default_value=default_site, description="site parameter file"),
        DeclareLaunchArgument("namespace", default_value="curve_250", description="site namespace"),
        DeclareLaunchArgument("source", description="history to replay (bag folder, .mcap, .db3 or .csv)"),
        DeclareLaunchArgument("output", default_value="", description="bag folder to record into"),
        DeclareLaunchArgument("rate", default_value="0.0",
                              description="replay speed: 0 as fast as the graph takes it, 1 recorded timing"),
        DeclareLaunchArgument("checkpoint", default_value="",
                              description="corrugation state file to resume from and checkpoint to ('' : none)"),
        Node(package="rail_monitor", executable="mcap_recorder", namespace=ns,
             parameters=[site, common, {"output": LaunchConfiguration("output")}]),
        Node(package="rail_monitor", executable="squeal_risk_model", namespace=ns, parameters=[site, common]),
        Node(package="rail_monitor", executable="corrugation_estimator", namespace=ns,
             parameters=[site, common, {"checkpoint_path": LaunchConfiguration("checkpoint")}]),
        Node(package="rail_monitor", executable="rolling_noise_predictor", namespace=ns, parameters=[site, common]),
        Node(package="rail_monitor", executable="alert_manager", namespace=ns, parameters=[site, common]),
        # The replayer starts once the recorder, the three models and the alert manager subscribe,
        # so no pass is lost.
        Node(package="rail_monitor", executable="pass_replayer", namespace=ns,
             parameters=[site, {"source": LaunchConfiguration("source"), "rate": LaunchConfiguration("rate"),
                                "wait_for_subscribers": 5}]),
    ])
