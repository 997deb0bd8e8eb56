"""The site a bag was made with, stored in the bag: the site file's text, its name and SHA-256,
and the software version.

The graph's recorder and batch mode write it twice, as rosbag2 readers and MCAP readers each look
for it: an MCAP metadata record named :data:`SITE_RECORD` in every file, and the same keys
(prefixed ``rail_monitor.site.``) in ``custom_data`` of ``metadata.yaml``. ``report`` and ``info``
read a bag with its own site; a bag whose two copies disagree is refused, like any bag that
disagrees with its own metadata.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from mcap.reader import make_reader

from rail_monitor import __version__
from rail_monitor.bagio.integrity import bag_files
from rail_monitor.core.errors import InputError
from rail_monitor.core.user_file import read_user_text

SITE_RECORD = "rail_monitor.site"
FIELDS = ("site_file", "site_file_name", "site_file_sha256", "software_version")


def site_record(path: str | Path) -> dict[str, str]:
    """The record of a site file (InputError if it cannot be read)."""
    path = Path(path)
    text = read_user_text(path, "a site file")
    return {"site_file": text, "site_file_name": path.name,
            "site_file_sha256": hashlib.sha256(text.encode()).hexdigest(), "software_version": __version__}


def custom_data(record: dict[str, str]) -> dict[str, str]:
    """The record as metadata.yaml custom_data entries."""
    return {f"{SITE_RECORD}.{k}": record[k] for k in FIELDS}


def _from_metadata(meta: dict[str, Any] | None) -> dict[str, str] | None:
    custom = (meta or {}).get("custom_data")
    if not isinstance(custom, dict) or f"{SITE_RECORD}.site_file" not in custom:
        return None
    return {k: str(custom.get(f"{SITE_RECORD}.{k}", "")) for k in FIELDS}


def _from_mcap(path: Path) -> dict[str, str] | None:
    try:
        with open(path, "rb") as f:
            for m in make_reader(f).iter_metadata():
                if m.name == SITE_RECORD:
                    return {k: str(m.metadata.get(k, "")) for k in FIELDS}
    except Exception as exc:  # a file the integrity check would refuse too
        raise InputError(f"{path}: cannot read its metadata records: {type(exc).__name__}: {exc}") from None
    return None


def read_site_record(bag: str | Path) -> dict[str, str] | None:
    """The site stored with a bag (None if it holds none: a bag of another recorder, or a CSV).
    InputError if the files disagree with each other or with metadata.yaml."""
    path = Path(bag)
    if path.suffix.lower() == ".csv" or not path.exists():
        return None
    files, meta = bag_files(path)
    found = {str(p.name): _from_mcap(p) for p in files if p.suffix == ".mcap"}
    yaml_copy = _from_metadata(meta)
    if yaml_copy is not None:
        found["metadata.yaml"] = yaml_copy
    records = [r for r in found.values() if r is not None]
    if not records:
        return None
    first = next(n for n, r in found.items() if r is not None)
    for name, r in found.items():
        if r is None:
            raise InputError(f"{path}: {name} stores no site file where {first} does: the bag "
                             "disagrees with itself")
        if r["site_file_sha256"] != records[0]["site_file_sha256"]:
            raise InputError(f"{path}: {name} stores another site file ({r['site_file_sha256'][:12]}) than "
                             f"{first} ({records[0]['site_file_sha256'][:12]}): the bag disagrees "
                             "with itself")
    if hashlib.sha256(records[0]["site_file"].encode()).hexdigest() != records[0]["site_file_sha256"]:
        raise InputError(f"{path}: the stored site file does not match its own SHA-256")
    return records[0]


def describe(record: dict[str, str]) -> str:
    """One line naming a stored site."""
    return (f"{record['site_file_name']} (sha256 {record['site_file_sha256'][:12]}, stored by rail_monitor "
            f"{record['software_version']})")
