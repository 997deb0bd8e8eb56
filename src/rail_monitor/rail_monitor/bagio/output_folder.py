"""Output folders: every folder rail_monitor creates carries a marker file, and only such a
folder may ever be replaced (``--overwrite``): nothing is deleted that the program did not create."""

from __future__ import annotations

import os
import shutil
import uuid
from dataclasses import dataclass
from pathlib import Path

from rail_monitor.core.errors import RailMonitorError

# A file the program leaves in every folder it creates: --overwrite replaces only such folders.
MARKER = ".rail_monitor"


def beside(source: str | Path, suffix: str) -> Path:
    """The default output of a command: <source name><suffix> in the folder that holds the source
    (a file's name without its .csv, .mcap or .db3)."""
    src = Path(source)
    src = src if src.name else src.absolute()
    return src.with_name(f"{src.stem if src.suffix.lower() in ('.csv', '.mcap', '.db3') else src.name}{suffix}")


@dataclass(frozen=True)
class Claim:
    """An output folder claimed by one run: its marker holds the run's token, so what the run
    deletes on failure is proven its own (made: the claim created the folder itself)."""

    folder: Path
    token: str
    made: bool

    def holds(self) -> bool:
        """Whether the folder's marker is still this claim's."""
        try:
            return self.token in (self.folder / MARKER).read_text(encoding="utf-8")
        except OSError:
            return False

    def empty(self) -> None:
        """Remove what the run wrote, keeping the folder and its claim (to write it again)."""
        if self.holds():
            for f in self.folder.iterdir():
                if f.name != MARKER:
                    shutil.rmtree(f) if f.is_dir() and not f.is_symlink() else f.unlink()

    def release(self) -> None:
        """Remove what the run wrote: the folder it made, or everything in the empty one it took."""
        if not self.holds():
            return  # not ours (any more): nothing is deleted
        if self.made:
            shutil.rmtree(self.folder)
            return
        self.empty()
        (self.folder / MARKER).unlink(missing_ok=True)


def claim_output_folder(folder: Path) -> Claim:
    """Create an output folder, or take an existing empty one, atomically: the folder's creation or
    the exclusive creation of its marker is the claim, so two runs never claim one folder.
    RailMonitorError (one line) for a file, a link, a folder that is not empty, or one another run
    claimed."""
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        raise RailMonitorError(f"{folder}: output exists and is not a folder (a file or a link)")
    token = f"{os.getpid()}-{uuid.uuid4().hex}"
    try:
        folder.parent.mkdir(parents=True, exist_ok=True)
        try:
            folder.mkdir()
            made = True
        except FileExistsError:
            made = False
        fd = os.open(folder / MARKER, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        raise RailMonitorError(f"{folder}: output folder exists and is not empty (another run's, or one "
                               "rail_monitor wrote before)") from None
    except OSError as exc:
        raise RailMonitorError(f"{folder}: cannot create the output folder: {exc.strerror}") from None
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(f"created by rail_monitor; --overwrite may replace this folder\nclaim {token}\n")
    claim = Claim(folder, token, made)
    if not made and any(f.name != MARKER for f in folder.iterdir()):
        (folder / MARKER).unlink(missing_ok=True)
        raise RailMonitorError(f"{folder}: output folder exists and is not empty")
    return claim


def new_output_folder(folder: Path, claim: Claim | None = None) -> Path:
    """The output folder of a writer: the one claim holds (it must still hold it and the folder
    must hold nothing else), else a folder claimed now (claim_output_folder)."""
    if claim is None:
        return claim_output_folder(folder).folder
    if claim.folder != folder or not claim.holds() or any(f.name != MARKER for f in folder.iterdir()):
        raise RailMonitorError(f"{folder}: not an empty output folder this run claimed")
    return folder
