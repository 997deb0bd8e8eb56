"""Message types for bags: the Jazzy standard types plus rail_msgs.

rosbags serialises and deserialises CDR without rclpy, so batch mode and the bag tools need
no ROS graph. rail_msgs' definitions ship with this package (``rail_monitor/msg``, the
interface package's own files), so a bag can be written where no ROS 2 is installed. Schema
texts are the .msg files (comments kept, as rosbag2 stores them): the standard types' from the
ament index where ROS 2 is installed, else rosbags' own definition of them (the same fields, no
comments). Type hashes are RIHS01, equal to those rosidl generates.
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
FRICTION_APPLICATOR = "rail_msgs/msg/FrictionApplicator"


SHIPPED_MSG = Path(__file__).parent.parent / "msg"  # rail_msgs' .msg files, package data


@functools.cache  # a package's place does not move while the process runs
def _share_dir(package: str) -> Path | None:
    """The package's share folder from the ament index (None without ROS 2 or the package)."""
    try:
        from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
    except ImportError:
        return None
    try:
        return Path(get_package_share_directory(package))
    except PackageNotFoundError:
        return None


def msg_file(typename: str) -> Path | None:
    """The .msg file of 'pkg/msg/Type': rail_msgs' shipped with this package, another package's
    from the ament index (None where it is not installed)."""
    pkg, _, name = typename.split("/")
    if pkg == "rail_msgs":
        return SHIPPED_MSG / f"{name}.msg"
    share = _share_dir(pkg)
    return None if share is None else share / "msg" / f"{name}.msg"


@functools.cache
def typestore() -> Typestore:
    """The Jazzy typestore with every rail_msgs message registered."""
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    paths = sorted(SHIPPED_MSG.glob("*.msg"))
    if not paths:
        raise RailMonitorError(f"no rail_msgs definitions in {SHIPPED_MSG}: the package is installed incompletely")
    for path in paths:
        types.update(get_types_from_msg(path.read_text(encoding="utf-8"), f"rail_msgs/msg/{path.stem}"))
    store.register(types)
    return store


@functools.cache
def schema_text(typename: str) -> str:
    """rosbag2 'ros2msg' schema: the type's .msg text, then each dependency after a separator.

    Dependencies (and their order) come from rosbags' generated definition; their texts are
    the .msg files where installed, so units and comments reach Foxglove and other readers, else
    rosbags' generated text of the type.
    """
    generated, _ = typestore().generate_msgdef(typename, ros_version=2)
    sections = re.split(rf"^{SEPARATOR}\n", generated, flags=re.MULTILINE)
    by_name = {m.group(1): m.group(2) for m in (re.match(r"MSG: (\S+)\n(.*)", part, re.S) for part in sections[1:])
               if m}
    parts = [msg_file(typename).read_text(encoding="utf-8").rstrip("\n")]
    for dep, own in by_name.items():
        pkg, name = dep.split("/")[0], dep.split("/")[-1]
        path = msg_file(f"{pkg}/msg/{name}")
        text = path.read_text(encoding="utf-8") if path is not None and path.is_file() else own
        parts.append(f"{SEPARATOR}\nMSG: {pkg}/{name}\n{text.rstrip(chr(10))}")
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
