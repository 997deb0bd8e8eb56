"""Parameter specifications: the one place where names, defaults, units and ranges live.

Nodes turn a :class:`ParamSpec` into a ROS 2 parameter with a descriptor; the pure loaders
(:func:`resolve`) apply the same specs to a site YAML file read without ROS, so the live graph,
the command line and batch mode agree on every default and every range.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from rail_monitor.core.errors import ConfigError

Value = bool | int | float | str | list[float] | list[int] | list[str]


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: name (dotted, relative), default, description with unit, allowed range."""

    name: str
    default: Value
    description: str
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] = ()
    tunable: bool = False  # may be changed on a running node (else read-only once declared)

    @property
    def annotation(self) -> Any:
        """The field type of the value (list[element] for arrays)."""
        return list[self.kind] if isinstance(self.default, list) else self.kind

    @property
    def kind(self) -> type:
        """The Python type of the value (list element type for arrays)."""
        d = self.default
        if isinstance(d, list):
            return type(d[0]) if d else float
        return type(d)

    def range_text(self) -> str:
        """The allowed values, for error messages and descriptors."""
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        lo = "-inf" if self.low is None else f"{self.low:g}"
        hi = "inf" if self.high is None else f"{self.high:g}"
        return f"[{lo}, {hi}]"

    def check(self, value: Any, where: str = "") -> Value:
        """Return value coerced to the spec's type, or raise ConfigError naming the parameter."""
        label = f"{where}{self.name}"
        want = self.kind
        is_list = isinstance(self.default, list)
        items = value if is_list else [value]
        if is_list and not isinstance(value, (list, tuple)):
            raise ConfigError(f"parameter '{label}' must be a list of {want.__name__}, got {value!r}")
        out = []
        for item in items:
            if want is float and isinstance(item, int) and not isinstance(item, bool):
                item = float(item)  # the pure loader is lenient where YAML is ambiguous
            if (want is bool and not isinstance(item, bool)) or (
                want is not bool and (isinstance(item, bool) or not isinstance(item, want))
            ):
                raise ConfigError(
                    f"parameter '{label}' must be {want.__name__}, got {type(item).__name__} {item!r}"
                )
            if want in (int, float):
                if isinstance(item, float) and not math.isfinite(item):
                    raise ConfigError(f"parameter '{label}' must be finite, got {item!r}")
                if (self.low is not None and item < self.low) or (self.high is not None and item > self.high):
                    raise ConfigError(f"parameter '{label}' = {item!r} is outside its range {self.range_text()}")
            if self.choices and item not in self.choices:
                raise ConfigError(f"parameter '{label}' = {item!r} is not {self.range_text()}")
            out.append(item)
        return out if is_list else out[0]


def resolve(specs: Sequence[ParamSpec], values: Mapping[str, Any], where: str = "",
            strict: bool = False) -> dict[str, Value]:
    """Apply specs to a flat mapping of dotted names: defaults filled in, every value checked.

    strict: a name no spec knows (a typo in the YAML) is a ConfigError instead of ignored.
    """
    if strict:
        refuse_unknown(values, {s.name for s in specs}, where)
    return {s.name: s.check(values[s.name], where) if s.name in values else s.default for s in specs}


ParamGroups = tuple[tuple[str, Sequence[ParamSpec]], ...]  # (name prefix, specs) a node declares


def help_lines(groups: ParamGroups) -> list[str]:
    """One line per parameter: name, type, allowed values, default, description (for --help)."""
    out = []
    for prefix, specs in groups:
        for s in specs:
            kind = f"{s.kind.__name__}[]" if isinstance(s.default, list) else s.kind.__name__
            allowed = "" if s.kind in (bool, str) and not s.choices else f", {s.range_text()}"
            out.append(f"  {prefix}{s.name} ({kind}{allowed}; default {s.default!r})\n      {s.description}")
    return out


def refuse_unknown(names: Collection[str], known: Collection[str], where: str = "") -> None:
    """ConfigError naming the first name (in sorted order) that is not known, with the nearest known one."""
    unknown = sorted(set(names) - set(known))
    if unknown:
        raise ConfigError(f"unknown parameter '{where}{unknown[0]}'{nearest_hint(unknown[0], known, where)}"
                          + (f" (and {len(unknown) - 1} more)" if len(unknown) > 1 else ""))


def nearest_hint(name: str, known: Collection[str], where: str = "") -> str:
    """'; did you mean ...?' with the known name nearest to name, or '' when none is close."""
    close = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.6)
    return f"; did you mean '{where}{close[0]}'?" if close else ""


def section(values: Mapping[str, Any], prefix: str) -> dict[str, Any]:
    """The values under a dotted prefix (e.g. 'squeal.'), with the prefix taken off their names."""
    return {k[len(prefix):]: v for k, v in values.items() if k.startswith(prefix)}


def attribute(name: str) -> str:
    """The attribute of a dotted parameter name in a values type (k_b.dry -> k_b_dry)."""
    return name.replace(".", "_")


def values_of(cls: type, values: Mapping[str, Any]) -> Any:
    """An instance of a section's values class (a frozen dataclass with one field per spec, dots as
    underscores: tests/core/test_params.py holds each to its specs) from values by dotted name."""
    return cls(**{attribute(k): v for k, v in values.items()})


def section_values(cls: type, specs: Sequence[ParamSpec], values: Mapping[str, Any], prefix: str) -> Any:
    """A section's checked values class from flat values (keys under prefix; a name the section's
    specs do not know is a ConfigError)."""
    return values_of(cls, resolve(specs, section(values, prefix), where=prefix, strict=True))


def flatten(tree: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Flatten a nested YAML mapping into dotted names, as ROS 2 parameter files do."""
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            flat.update(flatten(value, name + "."))
        else:
            flat[name] = value
    return flat
