"""Text from files and messages on its way to a terminal, a log or a report, made inert.

A topic name in a bag, a train id in a CSV or a vehicle class can hold anything: an ESC that
clears the screen or rewrites the line, a BEL, a bidirectional override that shows text in
another order, a line separator that forges a log line. :func:`printable` shows each such
character as its Python escape (``\\x1b``, ``\\u202e``) and leaves every other character alone.
"""

from __future__ import annotations

import unicodedata

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
