"""Train passes as a columnar table (numpy arrays), and their validation.

The same table feeds the live graph (one row per TrainPass message), batch mode (whole arrays)
and the bag and CSV readers and writers, so every path shares one validation and one set of
defaults. Field names, units and enumeration values mirror ``rail_msgs/msg/TrainPass``.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from rail_monitor.core.friction import (  # noqa: F401  (re-exported: the pass table's friction codes)
    FRICTION_BY_NAME,
    FRICTION_CONTAMINATED,
    FRICTION_DRY,
    FRICTION_MODIFIER,
    FRICTION_NAMES,
    FRICTION_UNSET,
    FRICTION_WET,
)
from rail_monitor.core.site import Site, VehicleClass
from rail_monitor.core.timeutil import NS_PER_S, TIME_MSG_END_NS, fits_time_msg

KMH_PER_MPS = 3.6  # speeds for people (CSV columns, exports, report) are in km/h

# Plausibility limits that separate a malformed event from an unusual pass.
MAX_SPEED_MPS = 120.0           # above any line speed at a curve
MIN_SPEED_MPS = 1.0             # below a walking pace: not a rolling pass (the models divide by the speed)
MIN_WHEEL_LOAD_N = 5.0e3        # half a tonne per wheel, under any empty vehicle (0 still means nominal)
MIN_TRAIN_LENGTH_M = 5.0        # shorter than any rail vehicle (0 still means from the class)
MAX_ANGLE_OF_ATTACK_RAD = 0.1   # 100 mrad: far past flange contact for any bogie
MAX_WHEEL_LOAD_N = 3.0e5        # 30 t axle load is about 147 kN per wheel
MAX_TRAIN_LENGTH_M = 5000.0
MAX_VEHICLE_COUNT = 500         # record heavy-haul trains run about 300 wagons in 3 km
MAX_AXLE_COUNT = 4 * MAX_VEHICLE_COUNT


@dataclass
class PassTable:
    """Columns of train passes; row i of every column is one pass (units as in TrainPass).

    stamp_ns is the pass time in nanoseconds since the Unix epoch (UTC).
    """

    stamp_ns: np.ndarray              # int64 [ns]
    train_id: np.ndarray              # str (object)
    vehicle_class: np.ndarray         # str (object)
    vehicle_count: np.ndarray         # int64 [-]
    axle_count: np.ndarray            # int64 [-]
    speed_mps: np.ndarray             # float64 [m/s]
    angle_of_attack_rad: np.ndarray   # float64 [rad]
    wheel_load_n: np.ndarray          # float64 [N]
    friction_state: np.ndarray        # int64, FRICTION_*
    train_length_m: np.ndarray        # float64 [m]

    DTYPES: ClassVar[dict[str, type]] = {
        "stamp_ns": np.int64, "train_id": object, "vehicle_class": object, "vehicle_count": np.int64,
        "axle_count": np.int64, "speed_mps": np.float64, "angle_of_attack_rad": np.float64,
        "wheel_load_n": np.float64, "friction_state": np.int64, "train_length_m": np.float64,
    }

    def __post_init__(self) -> None:
        n = None
        for f in fields(self):
            col = np.asarray(getattr(self, f.name), dtype=self.DTYPES[f.name])
            if col.ndim != 1 or (n is not None and len(col) != n):
                raise ValueError(f"column {f.name} must be 1-D with the same length as the others")
            n = len(col)
            setattr(self, f.name, col)

    @classmethod
    def columns(cls) -> list[str]:
        """The column names, in TrainPass field order."""
        return [f.name for f in fields(cls)]

    @classmethod
    def empty(cls) -> PassTable:
        return cls(**{name: [] for name in cls.columns()})

    @classmethod
    def from_rows(cls, rows: Iterable[Mapping[str, Any]]) -> PassTable:
        """Build a table from row mappings keyed by column name."""
        rows = list(rows)
        return cls(**{name: [r[name] for r in rows] for name in cls.columns()})

    @classmethod
    def concat(cls, tables: Sequence[PassTable]) -> PassTable:
        """The rows of the tables, one after the other."""
        return cls(**{name: np.concatenate([getattr(t, name) for t in tables]) for name in cls.columns()})

    def __len__(self) -> int:
        return len(self.stamp_ns)

    def row(self, i: int) -> dict[str, Any]:
        """Row i as a dict of Python scalars."""
        return {name: getattr(self, name)[i].item() if name not in ("train_id", "vehicle_class")
                else str(getattr(self, name)[i]) for name in self.columns()}

    def take(self, index: np.ndarray | Sequence[int] | slice) -> PassTable:
        """The rows selected by a boolean mask, an index array or a slice."""
        return PassTable(**{name: getattr(self, name)[index] for name in self.columns()})

    @functools.cached_property
    def class_groups(self) -> list[tuple[str, slice | np.ndarray]]:
        """(vehicle class, its rows) per class among the passes: a slice where the class's passes
        are one run (a table in class_order, or of one class), else a boolean mask (computed once:
        a table's columns are not changed in place)."""
        vc = self.vehicle_class
        if not len(vc):
            return []
        starts = np.flatnonzero(np.concatenate([[True], vc[1:] != vc[:-1]]))
        names = vc[starts].tolist()
        if len(set(names)) < len(names):
            return [(name, vc == name) for name in dict.fromkeys(names)]
        return [(name, slice(a, b)) for name, a, b in zip(names, starts.tolist(), [*starts[1:].tolist(), len(vc)],
                                                          strict=True)]

    def class_order(self) -> np.ndarray:
        """Indices that put the passes in runs of one class each (classes in order of first
        appearance, passes in their order within a class)."""
        vc = self.vehicle_class
        return np.concatenate([np.flatnonzero(vc == name) for name in dict.fromkeys(vc.tolist())] or
                              [np.zeros(0, np.intp)])

    def sorted(self) -> PassTable:
        """The rows in time order (stable, so equal stamps keep their order)."""
        return self.take(np.argsort(self.stamp_ns, kind="stable"))

    def equals(self, other: PassTable) -> bool:
        """True when every column is equal element by element (NaN equal to NaN)."""
        return len(self) == len(other) and all(
            np.array_equal(getattr(self, n), getattr(other, n), equal_nan=getattr(self, n).dtype.kind == "f")
            for n in self.columns()
        )


# Unicode's categories Cc (C0, DEL, C1), Zl (U+2028) and Zp (U+2029), as one character class: a C
# string or a terminal would act on them, or a log line would be split.
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")


_FRICTION_CODES = np.array(sorted(FRICTION_NAMES))


def _has_control(text: str) -> bool:
    """Whether text holds a control character (NUL, ESC, DEL, C1) or a line or paragraph separator."""
    return _CONTROL.search(text) is not None


def rejection_reasons(table: PassTable, site: Site | None = None) -> np.ndarray:
    """Why each pass is unusable: an array of strings, '' where the pass is valid.

    The first failing check names the reason. With a site, the vehicle class must be in its
    rolling-stock table. Checks are vectorised; the table is not modified.
    """
    n = len(table)
    whys = [""]
    bad: list[np.ndarray] = []

    def flag(mask: np.ndarray, why: str) -> None:
        whys.append(why)
        bad.append(mask)

    def first_failing() -> np.ndarray:
        """Per pass, the index in whys of its first failing check (0: none): one reduction over
        the checks' masks, not an update per check (most of the cost for a live pass)."""
        if not n:
            return np.zeros(0, np.intp)
        masks = np.array(bad)
        return np.where(masks.any(axis=0), masks.argmax(axis=0) + 1, 0)

    ids = table.train_id.tolist()
    flag(table.stamp_ns == 0, "stamp not set")
    flag(table.stamp_ns < 0, "stamp before 1970")
    flag(table.stamp_ns >= TIME_MSG_END_NS, "stamp past 2038-01-19 (builtin_interfaces/Time seconds are int32)")
    flag(np.fromiter(map(len, map(str.strip, ids)), np.int64, n) == 0, "empty train_id")
    flag(np.fromiter(map(len, ids), np.int64, n) > 64, "train_id longer than 64 characters")
    if _has_control("".join(ids)):  # rare: then pass by pass
        flag(np.array([_has_control(s) for s in ids], dtype=bool), "train_id has control or separator characters")
    bad_class = {c: _has_control(c) for c in set(table.vehicle_class.tolist())}  # few distinct classes
    flag(np.array([bad_class[c] for c in table.vehicle_class.tolist()], dtype=bool),
         "vehicle_class has control or separator characters")
    flag(~np.isfinite(table.speed_mps), "speed_mps not finite")
    flag(table.speed_mps <= 0.0, "speed_mps not positive")
    flag(table.speed_mps < MIN_SPEED_MPS, f"speed_mps below {MIN_SPEED_MPS:g} m/s")
    flag(table.speed_mps > MAX_SPEED_MPS, f"speed_mps above {MAX_SPEED_MPS:g} m/s")
    flag(~np.isfinite(table.angle_of_attack_rad), "angle_of_attack_rad not finite")
    flag(np.abs(table.angle_of_attack_rad) > MAX_ANGLE_OF_ATTACK_RAD,
         f"|angle_of_attack_rad| above {MAX_ANGLE_OF_ATTACK_RAD:g} rad")
    flag(~np.isfinite(table.wheel_load_n), "wheel_load_n not finite")
    flag(table.wheel_load_n < 0.0, "wheel_load_n negative")
    flag((table.wheel_load_n > 0.0) & (table.wheel_load_n < MIN_WHEEL_LOAD_N),
         f"wheel_load_n below {MIN_WHEEL_LOAD_N:g} N (0: the class's nominal load)")
    flag(table.wheel_load_n > MAX_WHEEL_LOAD_N, f"wheel_load_n above {MAX_WHEEL_LOAD_N:g} N")
    flag(~(table.friction_state[:, None] == _FRICTION_CODES).any(axis=1), "friction_state unknown")
    flag((table.axle_count == 0) & (table.vehicle_count == 0), "neither axle_count nor vehicle_count set")
    flag(table.vehicle_count > MAX_VEHICLE_COUNT, f"vehicle_count above {MAX_VEHICLE_COUNT}")
    flag(table.axle_count > MAX_AXLE_COUNT, f"axle_count above {MAX_AXLE_COUNT}")
    flag(~np.isfinite(table.train_length_m), "train_length_m not finite")
    flag(table.train_length_m < 0.0, "train_length_m negative")
    flag((table.train_length_m > 0.0) & (table.train_length_m < MIN_TRAIN_LENGTH_M),
         f"train_length_m below {MIN_TRAIN_LENGTH_M:g} m (0: from the counts and the class)")
    flag(table.train_length_m > MAX_TRAIN_LENGTH_M, f"train_length_m above {MAX_TRAIN_LENGTH_M:g} m")
    if site is not None:
        known = np.array([c in site.vehicles for c in table.vehicle_class], dtype=bool)
        flag(~known, "vehicle_class unknown to the site")
        # A zero length is filled from the counts and the class: that length must be plausible too
        # (a length given is checked above).
        fill = (first_failing() == 0) & (table.train_length_m == 0.0)
        implied = np.zeros(n)
        if fill.any():
            implied[fill] = with_class_defaults(table.take(fill), site).train_length_m
        flag(implied > MAX_TRAIN_LENGTH_M,
             f"train length from vehicle_count and the class's vehicle length above {MAX_TRAIN_LENGTH_M:g} m")
    return np.array(whys, dtype=object)[first_failing()]


def ahead_of_stream(stamp_ns: np.ndarray, usable: np.ndarray, newest_ns: int, margin_ns: int
                    ) -> tuple[np.ndarray, int]:
    """Which passes are stamped more than margin_ns [ns] after the newest pass taken before them.

    Passes are taken in the order given; a pass is taken when it is usable (valid otherwise) and
    not ahead. The reference starts at newest_ns (0: none yet, so the first usable pass sets it)
    and only a taken pass moves it: one far-future stamp is rejected, and every pass after it
    is judged against the real stream, not against that stamp. Returns (ahead mask, newest taken).
    """
    t = np.asarray(stamp_ns, dtype=np.int64)
    usable = np.asarray(usable, dtype=bool)
    ahead = np.zeros(len(t), dtype=bool)
    if not usable.any():
        return ahead, int(newest_ns)
    # Fast path (no pass ahead): the reference of pass i is the newest usable pass before it.
    before = np.maximum.accumulate(np.concatenate(([newest_ns], np.where(usable, t, 0))))[:-1]
    first = np.flatnonzero(usable & (before > 0) & (t - before > margin_ns))
    if len(first) == 0:
        return ahead, int(max(newest_ns, t[usable].max()))
    k = int(first[0])
    newest = int(before[k])
    for i in range(k, len(t)):  # a pass ahead leaves the reference where it was: judge the rest one by one
        if not usable[i]:
            continue
        if t[i] - newest > margin_ns:
            ahead[i] = True
        else:
            newest = max(newest, int(t[i]))
    return ahead, newest


def ahead_reason(margin_s: float, of: str) -> str:
    """The rejection reason of a pass stamped more than margin_s [s] after the stream or the clock."""
    days = margin_s / 86_400.0
    span = f"{days:g} d" if days == round(days) else f"{margin_s:g} s"
    return f"stamp more than {span} ahead of the {of} (stamps.max_ahead_of_{of}_s)"


def reject_ahead(stamp_ns: np.ndarray, reasons: np.ndarray, newest_ns: int, margins: Any,
                 clock_ns: int | None = None) -> int:
    """Mark, in ``reasons`` (in place), the otherwise valid passes stamped too far ahead: of the
    clock (when clock_ns is given: a live node not on sim time) by ``margins.max_ahead_of_clock_s``,
    then of the stream by ``margins.max_ahead_of_stream_s`` (:func:`ahead_of_stream`).

    margins: a :class:`rail_monitor.core.node_params.StampParams`. Returns the newest pass taken.
    """
    t = np.asarray(stamp_ns, dtype=np.int64)
    if clock_ns is not None and clock_ns > 0:
        late = (reasons == "") & (t - clock_ns > int(margins.max_ahead_of_clock_s * NS_PER_S))
        reasons[late] = ahead_reason(margins.max_ahead_of_clock_s, "clock")
    ahead, newest = ahead_of_stream(t, reasons == "", newest_ns, int(margins.max_ahead_of_stream_s * NS_PER_S))
    reasons[ahead] = ahead_reason(margins.max_ahead_of_stream_s, "stream")
    return newest


def publishable(table: PassTable, margins: Any, newest_ns: int = 0) -> tuple[PassTable, dict[str, int]]:
    """What a pass source sends, in time order, and how many it leaves out, by reason: a stamp
    builtin_interfaces/Time cannot hold, or one too far ahead of the stream (margins as in
    :func:`reject_ahead`; a replay at recorded timing would otherwise wait for it for years).
    newest_ns: the newest pass sent before these (0: none)."""
    fits = fits_time_msg(table.stamp_ns)
    table = table.take(fits).sorted()
    ahead, _ = ahead_of_stream(table.stamp_ns, table.stamp_ns > 0, newest_ns,
                               int(margins.max_ahead_of_stream_s * NS_PER_S))
    left_out = {"stamp not representable (builtin_interfaces/Time seconds are int32)": int((~fits).sum()),
                ahead_reason(margins.max_ahead_of_stream_s, "stream"): int(ahead.sum())}
    return table.take(~ahead), {why: n for why, n in left_out.items() if n}


def with_class_defaults(table: PassTable, site: Site) -> PassTable:
    """A copy with zero axle_count, wheel_load_n and train_length_m filled from the site's table.

    Rows must be valid for the site (see :func:`rejection_reasons`).
    """
    out = table.take(slice(None))
    for c in set(table.vehicle_class.tolist()):
        site.vehicle(c)  # a ConfigError naming the known classes for an unknown one
    axles = site.per_pass(table.vehicle_class, "axles_per_vehicle").astype(np.int64)
    load = site.per_pass(table.vehicle_class, "wheel_load_n").astype(np.float64)
    length = site.per_pass(table.vehicle_class, "vehicle_length_m").astype(np.float64)
    out.axle_count = np.where(out.axle_count == 0, out.vehicle_count * axles, out.axle_count)
    out.vehicle_count = np.where(out.vehicle_count == 0, -(-out.axle_count // axles), out.vehicle_count)
    out.wheel_load_n = np.where(out.wheel_load_n == 0.0, load, out.wheel_load_n)
    out.train_length_m = np.where(out.train_length_m == 0.0, out.vehicle_count * length, out.train_length_m)
    return out


def synthetic_passes(site: Site, cls: VehicleClass, speeds: np.ndarray, vehicles: int) -> PassTable:
    """One train of the class per speed [m/s], of ``vehicles`` vehicles, on dry rail, class defaults
    filled (the what-if's and the report's reference passes)."""
    n = len(speeds)
    return with_class_defaults(PassTable(
        stamp_ns=np.arange(1, n + 1), train_id=[f"speed {v:g}" for v in speeds], vehicle_class=[cls.name] * n,
        vehicle_count=[vehicles] * n, axle_count=[0] * n, speed_mps=speeds, angle_of_attack_rad=[0.0] * n,
        wheel_load_n=[0.0] * n, friction_state=[FRICTION_BY_NAME["dry"]] * n, train_length_m=[0.0] * n), site)


def accepted_passes(table: PassTable, site: Site) -> PassTable:
    """The rows the site accepts (:func:`rejection_reasons` empty), class defaults filled: what
    the models advance on."""
    return with_class_defaults(table.take(rejection_reasons(table, site) == ""), site)
