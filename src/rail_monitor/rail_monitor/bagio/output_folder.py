"""Output folders: every folder rail_monitor creates carries a marker file, and only such a
folder may ever be replaced (``--overwrite``): nothing is deleted that the program did not create."""

from __future__ import annotations

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


def mark_output(folder: Path) -> None:
    """Mark a folder as created by rail_monitor (see :data:`MARKER`)."""
    (folder / MARKER).write_text("created by rail_monitor; --overwrite may replace this folder\n", encoding="utf-8")


def new_output_folder(folder: Path) -> Path:
    """Create (or take, if empty) an output folder and mark it; RailMonitorError for anything else."""
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        raise RailMonitorError(f"{folder}: output exists and is not a folder (a file or a link)")
    if folder.exists() and any(folder.iterdir()):
        raise RailMonitorError(f"{folder}: output folder exists and is not empty")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        mark_output(folder)
    except OSError as exc:
        raise RailMonitorError(f"{folder}: cannot create the output folder: {exc.strerror}") from None
    return folder
