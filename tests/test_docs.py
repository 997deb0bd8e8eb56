"""The documentation as a user meets it (issue 24): the README's two commands first, links that
resolve, the generated parameters reference current, one version everywhere, nothing pointing
outside the repository."""

from __future__ import annotations

import ast
import re

import yaml

import rail_monitor
from rail_monitor.site_file import parameters_markdown

from conftest import TOP

PAGES = [TOP / "README.md", TOP / "CHANGELOG.md", *sorted((TOP / "docs").glob("*.md"))]


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_the_readme_starts_with_the_two_commands():
    first = re.search(r"```bash\n(.*?)```", (TOP / "README.md").read_text(), re.S).group(1).splitlines()
    assert [line.split()[:2] for line in first] == [["ros2_ws/run", "demo"], ["ros2_ws/run", "test"]]
    ci = (TOP / ".ci" / "run").read_text()
    assert "ros2_ws/run test" in ci  # CI calls the README's test command


def test_every_link_resolves():
    checked = 0
    for page in PAGES:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if target.startswith(("http://", "https://", "mailto:")):
                continue
            path, _, anchor = target.partition("#")
            dest = (page.parent / path).resolve() if path else page
            assert dest.is_file(), f"{page.name}: {target}"
            if anchor and dest.suffix == ".md":
                headings = re.findall(r"(?m)^#+ (.+)$", dest.read_text())
                assert anchor in {_slug(h) for h in headings}, f"{page.name}: {target}"
            checked += 1
    assert checked > 15


def test_the_parameters_reference_is_current():
    assert (TOP / "docs" / "parameters.md").read_text() == parameters_markdown(), (
        "regenerate: ros2_ws/run python -m rail_monitor.site_file > docs/parameters.md")


def test_nothing_points_outside_the_repository():
    files = [*PAGES, *(TOP / "src").rglob("*.py"), *(TOP / "src").rglob("*.yaml"), *(TOP / "src").rglob("*.msg")]
    for f in files:
        text = f.read_text()
        assert "../shared" not in text and "MODELS.md" not in text and "seed/" not in text, f


def test_one_version_everywhere():
    def xml_version(path):
        return re.search(r"<version>([^<]+)</version>", path.read_text()).group(1)

    version = xml_version(TOP / "src" / "rail_monitor" / "package.xml")
    assert xml_version(TOP / "src" / "rail_msgs" / "package.xml") == version == rail_monitor.__version__
    assert re.search(r"(?m)^## (\S+)", (TOP / "CHANGELOG.md").read_text()).group(1) == version
    citation = yaml.safe_load((TOP / "CITATION.cff").read_text())
    assert citation["version"] == version and citation["license"] == "Apache-2.0"
    assert "<license>Apache-2.0</license>" in (TOP / "src" / "rail_monitor" / "package.xml").read_text()
    assert "Apache License" in (TOP / "LICENSE").read_text() and "Version 2.0" in (TOP / "LICENSE").read_text()


# Public model functions are documented as pvlib documents its own (issue 53): numpydoc Parameters
# (each with its unit in brackets), Returns and References. Compiled twins are documented once, by
# the numpy function each names (one place for each computation); models.engine only chooses
# between numpy and numba kernels.
MODELS = TOP / "src" / "rail_monitor" / "rail_monitor" / "models"
NUMPYDOC_TWINS = {"corrugation_jit": ("corrugation_state",), "passby_axles_jit": ("passby_axles", "passby_axles_peak")}
NOT_MODELS = ("__init__", "engine")


def _numpydoc_sections(doc: str) -> dict[str, list[str]]:
    """A docstring's numpydoc sections: title -> its lines (a title is underlined with dashes)."""
    lines, out, title = doc.splitlines(), {}, None
    for i, line in enumerate(lines):
        if i + 1 < len(lines) and re.fullmatch(r"-{3,}", lines[i + 1].strip()) and line.strip():
            title = line.strip()
            out[title] = []
        elif title is not None and not re.fullmatch(r"-{3,}", line.strip()):
            out[title].append(line)
    return out


def _numpydoc_faults(fn: ast.FunctionDef) -> list[str]:
    doc = ast.get_docstring(fn) or ""
    sections = _numpydoc_sections(doc)
    names = [a.arg for a in (*fn.args.posonlyargs, *fn.args.args, *fn.args.kwonlyargs)]
    wanted = ("Parameters", "Returns", "References") if names else ("Returns", "References")
    faults = [f"no {s}" for s in wanted if s not in sections]
    entries: dict[str, str] = {}
    current: list[str] = []
    for line in sections.get("Parameters", []):
        if line and not line.startswith(" ") and " : " in line:
            current = [n.strip() for n in line.split(" : ")[0].split(",")]
            entries.update({n: line for n in current})
        else:
            entries.update({n: entries[n] + line for n in current})
    faults += [f"parameter {n} undocumented" for n in names if n not in entries]
    faults += [f"parameter {n} without a unit [..]" for n in names
               if n in entries and not re.search(r"\[[^\]]*\]", entries[n])]
    if "References" in sections and not any(".. [" in line for line in sections["References"]):
        faults.append("References without an entry")
    return faults


def _public_functions(name: str) -> list[ast.FunctionDef]:
    return [fn for fn in ast.parse((MODELS / f"{name}.py").read_text()).body
            if isinstance(fn, ast.FunctionDef) and not fn.name.startswith("_")]


def test_public_model_functions_are_documented_with_units_and_references():
    checked = 0
    for path in sorted(MODELS.glob("*.py")):
        if path.stem in NOT_MODELS or path.stem in NUMPYDOC_TWINS:
            continue
        for fn in _public_functions(path.stem):
            assert not _numpydoc_faults(fn), f"models/{path.name}: {fn.name}: {_numpydoc_faults(fn)}"
            checked += 1
    assert checked >= 150


def test_compiled_twins_name_the_documented_function_they_compile():
    for twin, documented in NUMPYDOC_TWINS.items():
        names = {f"{module}.{fn.name}" for module in documented for fn in _public_functions(module)}
        for fn in _public_functions(twin):
            named = re.findall(r"models\.(\w+\.\w+)", ast.get_docstring(fn) or "")
            assert named and set(named) <= names, f"models/{twin}.py: {fn.name} names no function of {documented}"
