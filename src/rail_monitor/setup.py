import re
from glob import glob
from pathlib import Path

from setuptools import find_packages, setup

package_name = "rail_monitor"
here = Path(__file__).resolve().parent
# The version is package.xml's (the one place it is set, as ament expects).
version = re.search(r"<version>([^<]+)</version>", (here / "package.xml").read_text()).group(1)
# What the ROS-free core (predict, simulate, batch, report, export) imports, at the versions pinned in
# ros2_ws/requirements.txt (the one place versions are set), for `pip install ./src/rail_monitor`
# without ROS 2. colcon installs with --single-version-externally-managed, which installs none.
CORE = ("numpy", "scipy", "numba", "matplotlib", "PyYAML", "ruamel.yaml", "rosbags", "mcap", "pandas", "pyarrow",
        "openpyxl", "tqdm", "threadpoolctl", "dask", "distributed", "tzdata")
pins = dict(line.split("==") for line in (here.parent.parent / "ros2_ws" / "requirements.txt").read_text().split()
            if "==" in line and not line.startswith("#"))
missing = [name for name in CORE if name not in pins]
if missing:
    raise SystemExit(f"ros2_ws/requirements.txt pins none of {missing}")

setup(
    name=package_name,
    version=version,
    packages=find_packages(exclude=["test", "tests"]),
    # msg/ and site_files/ are links to rail_msgs' definitions and the shipped site file (their one
    # place), copied into the package so that a plain pip install can write bags and find a site.
    package_data={package_name: ["data/*.csv", "msg/*.msg", "site_files/*.yaml"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{package_name}"]),
        (f"share/{package_name}", ["package.xml"]),
        (f"share/{package_name}/config", glob("config/*.yaml") + glob("config/*.xml") + glob("config/*.json")),
        (f"share/{package_name}/launch", glob("launch/*.py")),
    ],
    install_requires=["setuptools", *(f"{name}=={pins[name]}" for name in CORE)],
    python_requires=">=3.11",
    zip_safe=True,
    maintainer="rail_monitor developers",
    maintainer_email="rail-monitor@example.com",
    description="Wayside rail corrugation, rolling noise and squeal monitor for ROS 2 Jazzy.",
    license="Apache-2.0",
    entry_points={
        "console_scripts": [
            "pass_replayer = rail_monitor.nodes.pass_replayer:main",
            "pass_simulator = rail_monitor.nodes.pass_simulator:main",
            "mcap_recorder = rail_monitor.nodes.mcap_recorder:main",
            "squeal_risk_model = rail_monitor.nodes.squeal_risk_model:main",
            "corrugation_estimator = rail_monitor.nodes.corrugation_estimator:main",
            "rolling_noise_predictor = rail_monitor.nodes.rolling_noise_predictor:main",
            "alert_manager = rail_monitor.nodes.alert_manager:main",
            "foxglove_server = rail_monitor.nodes.foxglove_server:main",
            "wayside_monitor = rail_monitor.nodes.wayside_monitor:main",
            "noise_station = rail_monitor.nodes.noise_station:main",
            "site_engine = rail_monitor.nodes.site_engine:main",
            "grinding_planner = rail_monitor.nodes.grinding_planner:main",
            "rail-monitor = rail_monitor.cli:main",
        ],
    },
)
