"""Message types for bags: the Jazzy standard types plus rail_msgs, from the ament index.

rosbags serialises and deserialises CDR without rclpy, so batch mode and the bag tools need
no ROS graph. Schema texts are the installed .msg files (comments kept, as rosbag2 stores
them); type hashes are RIHS01, equal to those rosidl generates.
"""

from __future__ import annotations

import functools
import re
import struct
from pathlib import Path

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.timeutil import from_sec_nanosec

SEPARATOR = "=" * 80
TRAIN_PASS = "rail_msgs/msg/TrainPass"
CORRUGATION_STATE = "rail_msgs/msg/CorrugationState"
ROLLING_NOISE = "rail_msgs/msg/RollingNoise"
ROUGHNESS_SURVEY = "rail_msgs/msg/RoughnessSurvey"
MEASURED_PASS_NOISE = "rail_msgs/msg/MeasuredPassNoise"


@functools.cache  # a package's place does not move while the process runs
def _share_dir(package: str) -> Path:
    from ament_index_python.packages import PackageNotFoundError, get_package_share_directory

    try:
        return Path(get_package_share_directory(package))
    except PackageNotFoundError:
        raise RailMonitorError(
            f"package {package!r} is not in AMENT_PREFIX_PATH; source ros2_ws/install/setup.bash "
            "(or use ros2_ws/run)"
        ) from None


def msg_file(typename: str) -> Path:
    """The installed .msg file of 'pkg/msg/Type'."""
    pkg, _, name = typename.split("/")
    return _share_dir(pkg) / "msg" / f"{name}.msg"


@functools.cache
def typestore() -> Typestore:
    """The Jazzy typestore with every rail_msgs message registered."""
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for path in sorted((_share_dir("rail_msgs") / "msg").glob("*.msg")):
        types.update(get_types_from_msg(path.read_text(encoding="utf-8"), f"rail_msgs/msg/{path.stem}"))
    store.register(types)
    return store


@functools.cache
def schema_text(typename: str) -> str:
    """rosbag2 'ros2msg' schema: the type's .msg text, then each dependency after a separator.

    Dependencies (and their order) come from rosbags' generated definition; their texts are
    the installed .msg files, so units and comments reach Foxglove and other readers.
    """
    generated, _ = typestore().generate_msgdef(typename, ros_version=2)
    deps = re.findall(r"^MSG: (\S+)$", generated, flags=re.MULTILINE)
    parts = [msg_file(typename).read_text(encoding="utf-8").rstrip("\n")]
    for dep in deps:
        pkg, name = dep.split("/")[0], dep.split("/")[-1]
        text = msg_file(f"{pkg}/msg/{name}").read_text(encoding="utf-8").rstrip("\n")
        parts.append(f"{SEPARATOR}\nMSG: {pkg}/{name}\n{text}")
    return "\n".join(parts) + "\n"


def type_hash(typename: str) -> str:
    """RIHS01 type hash of a message type (as rosidl generates it)."""
    return typestore().hash_rihs01(typename)


def starts_with_header(typename: str) -> bool:
    """True when the message's first field is a std_msgs/Header (its stamp leads the CDR data)."""
    fields = typestore().fielddefs[typename][1]
    return bool(fields) and fields[0][1][1] == "std_msgs/msg/Header"


def header_stamp_ns(cdr: bytes) -> int | None:
    """header.stamp [ns] of a CDR message whose first field is a std_msgs/Header, or None.

    CDR: a 4-byte encapsulation header (byte 1: 1 little-endian, 0 big-endian), then
    stamp.sec (int32) and stamp.nanosec (uint32).
    """
    if len(cdr) < 12:
        return None
    order = "<" if cdr[1] == 1 else ">"
    sec, nanosec = struct.unpack_from(order + "iI", cdr, 4)
    return from_sec_nanosec(sec, nanosec)
