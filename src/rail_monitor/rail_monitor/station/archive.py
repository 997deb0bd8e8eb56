"""The audio a station keeps: the passes worth hearing, within a disk budget, with no silent drop.

A pass's audio is copied from the recorder's folder (never written to) into the archive when it
squeals, when it is a wheel-defect suspect (known later, from its residual), or while it is among
the ``loudest_per_day`` loudest passes (LpAFmax) of its UTC day. A pass that a louder one pushes out
of its day's loudest, with no other reason to stay, is removed. When a copy would overrun the
budget, kept files are removed to make room, lowest reason first (loudest of its day, then
wheel-defect suspect, then squeal) and oldest first within a reason, but never one of a higher
reason than the newcomer's, nor a newer one of the same reason; when that cannot make room the
newcomer is not kept. Every removal and every pass not kept is counted by reason and reported.

The archive's index (``index.json``, rewritten whole and atomically) lists the files the station
put there; only those are ever removed, and only they count against the budget.
"""

from __future__ import annotations

import bisect
import json
import os
import shutil
from collections import Counter
from dataclasses import asdict, dataclass, field
from pathlib import Path

from rail_monitor.core.errors import InputError
from rail_monitor.core.timeutil import NS_PER_S
from rail_monitor.core.user_file import read_user_text

SQUEAL, SUSPECT, LOUDEST = "squeal", "wheel defect suspect", "loudest of its day"
RANK = {LOUDEST: 1, SUSPECT: 2, SQUEAL: 3}  # which reason outlasts which when the budget is short
INDEX = "index.json"
NS_PER_DAY = 86_400 * NS_PER_S
DAYS_RANKED = 2  # days before the newest pass's whose loudest are still ranked (a late pass of yesterday)


@dataclass
class Kept:
    """A pass whose audio is in the archive."""

    name: str
    stamp_ns: int
    train_id: str
    size: int                 # [byte]
    lpafmax_db: float         # [dB(A)]
    reasons: list[str] = field(default_factory=list)

    @property
    def rank(self) -> int:
        return max(RANK[r] for r in self.reasons)


class AudioArchive:
    """The kept audio of one station (folder, budget [byte], loudest passes kept per day)."""

    def __init__(self, folder: str | Path, budget_bytes: int, loudest_per_day: int) -> None:
        self.folder = Path(folder)
        self.budget = int(budget_bytes)
        self.loudest_per_day = int(loudest_per_day)
        self.counts: Counter[str] = Counter()
        self.notes: list[str] = []  # what was removed or not kept, for the owner to report (take_notes)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.kept: dict[tuple[int, str], Kept] = self._read_index()
        self.day_top: dict[int, list[tuple[float, tuple[int, str]]]] = {}  # each day's loudest heard
        for key, k in self.kept.items():
            if LOUDEST in k.reasons:
                bisect.insort(self.day_top.setdefault(k.stamp_ns // NS_PER_DAY, []), (k.lpafmax_db, key))

    def _read_index(self) -> dict[tuple[int, str], Kept]:
        path = self.folder / INDEX
        if not (path.exists() or path.is_symlink()):
            return {}
        return {(k.stamp_ns, k.train_id): k for k in read_index(path) if (self.folder / k.name).is_file()}

    @property
    def used_bytes(self) -> int:
        return sum(k.size for k in self.kept.values())

    def take_notes(self) -> list[str]:
        notes, self.notes = self.notes, []
        return notes

    def offer(self, source: str | Path, stamp_ns: int, train_id: str, lpafmax_db: float, squeals: bool) -> list[str]:
        """A heard pass: its audio kept when it is worth hearing; the reasons it is kept for."""
        reasons = [SQUEAL] if squeals else []
        if self.loudest_per_day > 0 and self._among_loudest(stamp_ns, train_id, lpafmax_db):
            reasons.append(LOUDEST)
        return self._keep(Path(source), stamp_ns, train_id, lpafmax_db, reasons)

    def suspect(self, source: str | Path, stamp_ns: int, train_id: str, lpafmax_db: float) -> list[str]:
        """A pass found a wheel-defect suspect (source: where its audio was)."""
        if (stamp_ns, train_id) not in self.kept and not Path(source).is_file():
            self.counts["suspect's audio no longer at hand"] += 1
            self.notes.append(f"wheel-defect suspect {train_id}: its audio is no longer in the recorder's folder")
            return []
        return self._keep(Path(source), stamp_ns, train_id, lpafmax_db, [SUSPECT])

    def _among_loudest(self, stamp_ns: int, train_id: str, level: float) -> bool:
        """Whether the pass is among its day's loudest heard so far (kept or not since); the
        quietest it pushes out loses that reason, and its file when it has no other."""
        day, key = stamp_ns // NS_PER_DAY, (stamp_ns, train_id)
        top = self.day_top.setdefault(day, [])  # (LpAFmax, key), quietest first
        for old in [d for d in self.day_top if d < day - DAYS_RANKED]:
            del self.day_top[old]
        if any(k == key for _, k in top):
            return True
        if len(top) >= self.loudest_per_day:
            if level <= top[0][0]:
                return False
            _, out_key = top.pop(0)
            out = self.kept.get(out_key)
            if out is not None and LOUDEST in out.reasons:
                out.reasons.remove(LOUDEST)
                if not out.reasons:
                    self._remove(out, "removed: no longer among its day's loudest")
        bisect.insort(top, (level, key))
        return True

    def _keep(self, source: Path, stamp_ns: int, train_id: str, level: float, reasons: list[str]) -> list[str]:
        if not reasons:
            return []
        key = (stamp_ns, train_id)
        if key in self.kept:  # heard again (a replay), or a reason more
            have = self.kept[key]
            have.reasons.extend(r for r in reasons if r not in have.reasons)
            self._write_index()
            return list(have.reasons)
        new = Kept(source.name, stamp_ns, train_id, source.stat().st_size, float(level), list(reasons))
        if not self._make_room(new):
            self.counts[f"not kept ({' and '.join(reasons)}): over the disk budget"] += 1
            self.notes.append(f"audio of {train_id} ({' and '.join(reasons)}) not kept: the archive is full of "
                              "passes kept for better reasons")
            self._write_index()
            return []
        part = self.folder / (new.name + ".part")
        shutil.copyfile(source, part)
        os.replace(part, self.folder / new.name)
        self.kept[key] = new
        self.counts[f"kept: {reasons[0]}"] += 1
        self._write_index()
        return list(reasons)

    def _make_room(self, new: Kept) -> bool:
        """Remove what the budget asks for to take new; False (nothing removed) when it cannot."""
        need = self.used_bytes + new.size - self.budget
        if need <= 0:
            return True
        victims = sorted((k for k in self.kept.values() if (k.rank, k.stamp_ns) < (new.rank, new.stamp_ns)),
                         key=lambda k: (k.rank, k.stamp_ns))
        chosen, freed = [], 0
        for k in victims:
            if freed >= need:
                break
            chosen.append(k)
            freed += k.size
        if freed < need:
            return False
        for k in chosen:
            self._remove(k, f"removed ({' and '.join(k.reasons)}) to stay within the disk budget")
        return True

    def _remove(self, k: Kept, why: str) -> None:
        (self.folder / k.name).unlink(missing_ok=True)
        del self.kept[(k.stamp_ns, k.train_id)]
        self.counts[why] += 1
        self.notes.append(f"audio of {k.train_id} {why}")

    def _write_index(self) -> None:
        rows = [asdict(k) for k in sorted(self.kept.values(), key=lambda k: (k.stamp_ns, k.train_id))]
        tmp = self.folder / (INDEX + ".part")
        tmp.write_text(json.dumps(rows, indent=0), encoding="utf-8")
        os.replace(tmp, self.folder / INDEX)


def read_index(path: str | Path) -> list[Kept]:
    """The entries of an archive's index (InputError, one line naming it, for anything else)."""
    try:
        kept = [Kept(**row) for row in json.loads(read_user_text(path, "an audio archive's index"))]
        if any(not k.reasons or not set(k.reasons) <= set(RANK) or "/" in k.name for k in kept):
            raise ValueError("an entry has no reason, an unknown one, or a name with a folder")
    except InputError:
        raise
    except (ValueError, TypeError, RecursionError) as exc:
        why = "nested too deeply" if isinstance(exc, RecursionError) else str(exc)
        raise InputError(f"{path}: not this station's archive index ({why}); move it away to start a new "
                         "archive (the files it lists are then never removed)") from None
    return kept
