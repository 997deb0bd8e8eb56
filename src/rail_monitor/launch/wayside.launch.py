"""Launch the wayside graph as separate processes on a full ROS 2 Jazzy install.

    ros2 launch rail_monitor wayside.launch.py source:=/path/to/history output:=/path/to/bag

Every node reads the site file and runs under the site's namespace on pass time (/clock). The
processes are those of rail_monitor.nodes.layout (the layout the tests run). When the replayer
has sent the whole history and the graph has taken it, it exits and the launch shuts down; Ctrl-C
stops every process cleanly at any moment.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, EmitEvent, RegisterEventHandler
from launch.event_handlers import OnProcessExit
from launch.events import Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node
from launch_ros.parameter_descriptions import ParameterValue

from rail_monitor.nodes.layout import FLOAT_ARGUMENTS, PROCESSES, SOURCE


def _argument(name: str):
    value = LaunchConfiguration(name)
    return ParameterValue(value, value_type=float) if name in FLOAT_ARGUMENTS else value


def generate_launch_description() -> LaunchDescription:
    default_site = os.path.join(get_package_share_directory("rail_monitor"), "config", "curve_250.yaml")
    site = LaunchConfiguration("site")
    ns = LaunchConfiguration("namespace")
    actions = [
        DeclareLaunchArgument("site", default_value=default_site, description="site parameter file"),
        DeclareLaunchArgument("namespace", default_value="curve_250", description="site namespace"),
        DeclareLaunchArgument("source", description="history to replay (bag folder, .mcap, .db3 or .csv)"),
        DeclareLaunchArgument("output", default_value="", description="bag folder to record into"),
        DeclareLaunchArgument("rate", default_value="0.0",
                              description="replay speed: 0 as fast as the graph takes it, 1 recorded timing, "
                                          "k k-times faster (a number: 10 or 10.0)"),
        DeclareLaunchArgument("checkpoint", default_value="",
                              description="corrugation state file to resume from and checkpoint to ('' : none)"),
    ]
    for p in PROCESSES:
        params = {**p.parameters, **{name: _argument(arg) for name, arg in p.arguments.items()}}
        if p.sim_time:
            params["use_sim_time"] = True
        node = Node(package="rail_monitor", executable=p.executable, namespace=ns, parameters=[site, params],
                    output="screen")
        actions.append(node)
        if p.executable == SOURCE:
            actions.append(RegisterEventHandler(OnProcessExit(
                target_action=node, on_exit=[EmitEvent(event=Shutdown(reason="the replay is finished"))])))
    return LaunchDescription(actions)
