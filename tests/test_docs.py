"""The documentation as a user meets it (issue 24): the README's two commands first, links that
resolve, the generated parameters reference current, one version everywhere, nothing pointing
outside the repository."""

from __future__ import annotations

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
