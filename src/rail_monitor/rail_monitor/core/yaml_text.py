"""YAML a user wrote, read safely: any fault is one line naming where it came from (no rclpy)."""

from __future__ import annotations

import re
from typing import Any

import yaml

from rail_monitor.core.errors import InputError, RailMonitorError

MAX_DEPTH = 100  # a site file nests 5 levels, a bag's metadata 6; deeper is not a document of ours
MAX_NODES = 1_000_000  # values once aliases are expanded: a few aliases can stand for billions


class _TooLarge(Exception):
    pass


def load_yaml(text: str, where: str, error: type[RailMonitorError] = InputError) -> Any:
    """text parsed as YAML (safe types only). A syntax fault, a value the parser cannot build (an
    integer of more than 4300 digits), nesting deeper than MAX_DEPTH, or aliases that expand to
    more than MAX_NODES values (a "billion laughs" document) is one ``error`` naming ``where``."""
    try:
        if _flow_depth(text) > MAX_DEPTH:  # before the parser, which takes seconds over 20,000 '['
            raise RecursionError
        doc = yaml.safe_load(text)
        _check_shape(doc)
    except yaml.YAMLError as exc:
        raise error(f"{where}: not valid YAML: {(str(exc).splitlines() or [''])[0]}") from None
    except RecursionError:
        raise error(f"{where}: nested too deeply to read (more than {MAX_DEPTH} levels)") from None
    except _TooLarge:
        raise error(f"{where}: its aliases expand to more than {MAX_NODES} values") from None
    except Exception as exc:  # a scalar the constructor refuses (ValueError, OverflowError)
        raise error(f"{where}: not valid YAML: {type(exc).__name__}: {(str(exc).splitlines() or [''])[0]}") from None
    return doc


_FLOW = re.compile(r"""[\[\]{}'"#\n\\]""")


def _flow_depth(text: str) -> int:
    """The deepest nesting of flow collections ([ ], { }) in YAML text, outside quotes and comments
    (the scan stops as soon as it passes MAX_DEPTH). A quote or bracket inside a plain scalar may
    miscount it; load_yaml's check of the parsed document stays the rule."""
    depth = deepest = 0
    quote, comment, skip_at = "", False, -1
    for m in _FLOW.finditer(text):
        c, at = m.group(), m.start()
        if at == skip_at:  # escaped by a backslash in a double-quoted string
            continue
        if comment:
            comment = c != "\n"
        elif quote:
            if c == "\\" and quote == '"':
                skip_at = at + 1
            elif c == quote:
                quote = ""
        elif c in "'\"":
            quote = c
        elif c == "#" and (at == 0 or text[at - 1] in " \t\n"):
            comment = True
        elif c in "[{":
            depth += 1
            deepest = max(deepest, depth)
            if deepest > MAX_DEPTH:
                break
        elif c in "]}":
            depth = max(depth - 1, 0)
    return deepest


def _check_shape(doc: Any) -> None:
    """RecursionError past MAX_DEPTH levels, _TooLarge past MAX_NODES expanded values; level by level,
    each distinct value once with how often aliases repeat it, so neither check itself recurses or
    expands anything."""
    level: dict[int, tuple[Any, int]] = {id(doc): (doc, 1)}
    total = 1
    for _ in range(MAX_DEPTH + 1):
        below: dict[int, tuple[Any, int]] = {}
        for value, times in level.values():
            children = value.values() if isinstance(value, dict) else value if isinstance(value, list) else ()
            for child in children:
                seen = below.get(id(child))
                below[id(child)] = (child, times + (seen[1] if seen else 0))
                total += times
            if total > MAX_NODES:
                raise _TooLarge
        if not below:
            return
        level = below
    raise RecursionError
