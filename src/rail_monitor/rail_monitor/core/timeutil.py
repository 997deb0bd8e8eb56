"""Time conversions, in one place: ISO 8601 text, ns since the Unix epoch, (sec, nanosec)."""

from __future__ import annotations

import re
from datetime import UTC, datetime
from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

from rail_monitor.core.errors import ConfigError, RailMonitorError

NS_PER_S = 1_000_000_000
NS_PER_HOUR = 3600 * NS_PER_S
NS_PER_DAY = 86400 * NS_PER_S
# builtin_interfaces/Time holds int32 seconds: the first instant it cannot hold (2038-01-19T03:14:08Z).
TIME_MSG_END_NS = 2**31 * NS_PER_S
INT64_MAX = 2**63 - 1
_ISO = re.compile(r"^(\d{4}-\d\d-\d\d[T ]\d\d:\d\d:\d\d)(?:\.(\d{1,9}))?(Z|[+-]\d\d:?\d\d)?$")


def window_end_ns(stamp_ns: int, interval_ns: int) -> int:
    """The end of the window (k w, (k + 1) w] holding stamp_ns [ns], windows of w = interval_ns
    counted from the Unix epoch (UTC): the same in every process."""
    return -(-int(stamp_ns) // interval_ns) * interval_ns


def parse_iso_ns(text: str) -> int:
    """ISO 8601 time with up to 9 fractional digits (Z, an offset, or naive = UTC) -> ns."""
    m = _ISO.match(text.strip())
    if not m:
        raise RailMonitorError(f"not an ISO 8601 time: {text!r}")
    whole, frac, zone = m.groups()
    try:
        t = datetime.fromisoformat(whole + ("+00:00" if zone in (None, "Z") else zone))
    except ValueError:
        raise RailMonitorError(f"not a valid time: {text!r}") from None
    return checked_ns(int(t.timestamp()) * NS_PER_S + int((frac or "0").ljust(9, "0")))


def checked_ns(ns: int) -> int:
    """ns since the epoch, refused (RailMonitorError) where an int64 cannot hold it."""
    if not -INT64_MAX <= ns <= INT64_MAX:
        raise RailMonitorError(f"time {ns} ns is out of range (int64 nanoseconds since 1970)")
    return ns


def fits_time_msg(ns):
    """Whether builtin_interfaces/Time (int32 seconds) can hold ns since the epoch (an int, or an
    int64 array, element by element)."""
    return (ns >= -TIME_MSG_END_NS) & (ns < TIME_MSG_END_NS)


def format_iso_ns(ns: int) -> str:
    """ns since the epoch -> 'YYYY-MM-DDTHH:MM:SS.fffffffffZ' (UTC, lossless)."""
    sec, frac = divmod(int(ns), NS_PER_S)
    return datetime.fromtimestamp(sec, UTC).strftime("%Y-%m-%dT%H:%M:%S") + f".{frac:09d}Z"


def iso_day(ns: int) -> str:
    """ns since the epoch -> its UTC day 'YYYY-MM-DD' ('never' for 0: no date)."""
    return format_iso_ns(ns)[:10] if ns else "never"


def time_zone(name: str):
    """The IANA time zone called name (ConfigError with one line if none is)."""
    try:
        return ZoneInfo(name)
    except (ZoneInfoNotFoundError, ValueError):
        raise ConfigError(f"time_zone {name!r} is not an IANA time zone (e.g. 'UTC', 'Australia/Brisbane', "
                          "'Europe/Berlin')") from None


def format_local_ns(ns: int, zone: str, seconds: bool = False) -> str:
    """ns since the epoch as local time of an IANA zone: 'YYYY-MM-DD HH:MM' (with :SS if seconds)
    and the zone's abbreviation, for people (format_iso_ns is the lossless form)."""
    t = datetime.fromtimestamp(int(ns) // NS_PER_S, UTC).astimezone(time_zone(zone))
    return t.strftime("%Y-%m-%d %H:%M:%S %Z" if seconds else "%Y-%m-%d %H:%M %Z")


def to_sec_nanosec(ns: int) -> tuple[int, int]:
    """ns since the epoch -> (sec, nanosec) as in builtin_interfaces/Time."""
    return divmod(int(ns), NS_PER_S)


def from_sec_nanosec(sec: int, nanosec: int) -> int:
    """builtin_interfaces/Time fields -> ns since the epoch."""
    return int(sec) * NS_PER_S + int(nanosec)
