import re
from glob import glob
from pathlib import Path

from setuptools import find_packages, setup

package_name = "rail_monitor"
# The version is package.xml's (the one place it is set, as ament expects).
version = re.search(r"<version>([^<]+)</version>", (Path(__file__).parent / "package.xml").read_text()).group(1)

setup(
    name=package_name,
    version=version,
    packages=find_packages(exclude=["test", "tests"]),
    package_data={package_name: ["data/*.csv"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{package_name}"]),
        (f"share/{package_name}", ["package.xml"]),
        (f"share/{package_name}/config", glob("config/*.yaml") + glob("config/*.xml") + glob("config/*.json")),
        (f"share/{package_name}/launch", glob("launch/*.py")),
    ],
    install_requires=["setuptools"],
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
            "rail-monitor = rail_monitor.cli:main",
        ],
    },
)
