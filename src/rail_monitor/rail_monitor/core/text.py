"""Text from files and messages on its way to a terminal, a log or a report, made inert; data
on its way to strict JSON.

A topic name in a bag, a train id in a CSV or a vehicle class can hold anything: an ESC that
clears the screen or rewrites the line, a BEL, a bidirectional override that shows text in
another order, a line separator that forges a log line. :func:`printable` shows each such
character as its Python escape (``\\x1b``, ``\\u202e``) and leaves every other character alone.
"""

from __future__ import annotations

import math
import unicodedata
from typing import Any

import numpy as np

# Control, format (bidi overrides, zero-width), line and paragraph separators, surrogates
# (undecodable bytes), private-use and unassigned code points.
_ESCAPED_CATEGORIES = frozenset({"Cc", "Cf", "Zl", "Zp", "Cs", "Co", "Cn"})


def _escape(c: str) -> str:
    o = ord(c)
    return f"\\x{o:02x}" if o < 0x100 else f"\\u{o:04x}" if o < 0x10000 else f"\\U{o:08x}"


def printable(text: object) -> str:
    """str(text) with every control, format or separator character shown as its escape."""
    s = str(text)
    if s.isprintable():
        return s
    return "".join(_escape(c) if unicodedata.category(c) in _ESCAPED_CATEGORIES else c for c in s)


def jsonable(data: Any) -> Any:
    """data with numpy scalars and arrays as Python numbers and lists, and every non-finite number
    (inf: "never", NaN: "none") as None: strict JSON, which jq and JavaScript parse."""
    if isinstance(data, dict):
        return {str(k): jsonable(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [jsonable(v) for v in data]
    if isinstance(data, np.ndarray):
        return jsonable(data.tolist())
    if isinstance(data, np.generic):
        data = data.item()
    if isinstance(data, float) and not math.isfinite(data):
        return None
    if data is None or isinstance(data, (str, int, float, bool)):
        return data
    return None  # an object JSON does not know
