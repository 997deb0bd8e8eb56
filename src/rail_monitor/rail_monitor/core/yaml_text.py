"""YAML a user wrote, read safely: any fault is one line naming where it came from (no rclpy)."""

from __future__ import annotations

from typing import Any

import yaml

from rail_monitor.core.errors import InputError, RailMonitorError


def load_yaml(text: str, where: str, error: type[RailMonitorError] = InputError) -> Any:
    """text parsed as YAML (safe types only). A syntax fault, or nesting deeper than the parser or
    any later walk of the document can follow, is one ``error`` naming ``where``."""
    try:
        doc = yaml.safe_load(text)
        _depth(doc)
    except yaml.YAMLError as exc:
        raise error(f"{where}: not valid YAML: {str(exc).splitlines()[0]}") from None
    except RecursionError:
        raise error(f"{where}: nested too deeply to read (more than {MAX_DEPTH} levels)") from None
    return doc


MAX_DEPTH = 100  # a site file nests 5 levels, a bag's metadata 6; deeper is not a document of ours


def _depth(doc: Any) -> None:
    """RecursionError for a document nested more than MAX_DEPTH levels (before anything recurses)."""
    level = [doc]
    for _ in range(MAX_DEPTH + 1):
        level = [v for x in level for v in (x.values() if isinstance(x, dict) else x if isinstance(x, list) else ())]
        if not level:
            return
    raise RecursionError
