"""Rewrite the manylinux include folders baked into the ros-jazzy wheels' CMake exports.

The wheels were built under /opt/python/cp311-cp311; their exported targets name that
interpreter's include folder and numpy's, which do not exist here, so CMake's generate step
fails for any interface package depending on builtin_interfaces (ROS2_WHEELS.md, "One known
defect"). We point them at this interpreter's folders. Idempotent: run after every install.
"""

from __future__ import annotations

import re
import sys
import sysconfig
from pathlib import Path

import numpy

# The two folders the wheels name, as regexes that also match an already-rewritten path is not
# needed: once rewritten, the manylinux prefix is gone and the file is left alone.
_BAD_NUMPY = re.compile(r"/opt/python/cp3\d+-cp3\d+/lib/python3\.\d+/site-packages/numpy/_core/include")
_BAD_PYTHON = re.compile(r"/opt/python/cp3\d+-cp3\d+/include/python3\.\d+")


def fix(prefix: Path) -> int:
    """Rewrite every *.cmake under prefix/share; return the number of files changed."""
    python_inc = sysconfig.get_paths()["include"]
    numpy_inc = numpy.get_include()
    changed = 0
    for path in (prefix / "share").rglob("*.cmake"):
        text = path.read_text(encoding="utf-8", errors="surrogateescape")
        if "/opt/python/" not in text:
            continue
        new = _BAD_PYTHON.sub(python_inc, _BAD_NUMPY.sub(numpy_inc, text))
        if new != text:
            path.write_text(new, encoding="utf-8", errors="surrogateescape")
            changed += 1
    return changed


if __name__ == "__main__":
    n = fix(Path(sys.argv[1] if len(sys.argv) > 1 else sys.prefix))
    print(f"fix_cmake_paths: {n} CMake file(s) rewritten")
