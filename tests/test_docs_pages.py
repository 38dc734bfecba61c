"""The documentation is short pages, one per capability, and the reference is generated from the
docstrings (``tests/test_api_reference.py``): ``docs/*.md`` stay under 3,000 lines in all, every page
linked from README's map stays near 200 lines with a command to type and one figure, and every relative
link and image of README.md and the pages names a file that exists."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from test_doc_commands import FENCE

ROOT = Path(__file__).resolve().parent.parent
PAGES = sorted((ROOT / "docs").glob("*.md"))
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
MAX_TOTAL_LINES = 3000
MAX_PAGE_LINES = 200
#: Pages of README's map without a figure of their own, with the reason.
NO_FIGURE = {
    "formats.md": "the file formats every capability reads: a reference, no result to draw",
    "detectors.md": "the contract every detector follows: a reference, no result to draw",
    "scale.md": "runs the other capabilities over fleets and catalogues: their figures are its output",
}


def _map_pages() -> list[Path]:
    """The pages README's "What it does" table links, in its order."""
    text = (ROOT / "README.md").read_text()
    table = text.split("## What it does", 1)[1].split("\n## ", 1)[0]
    names = dict.fromkeys(re.findall(r"\]\((docs/[\w-]+\.md)\)", table))
    return [ROOT / name for name in names]


def test_the_pages_are_short_in_all() -> None:
    total = sum(len(page.read_text().splitlines()) for page in PAGES)
    assert total < MAX_TOTAL_LINES, f"docs/*.md hold {total} lines"


@pytest.mark.parametrize("page", _map_pages(), ids=lambda p: p.name)
def test_a_capability_page_is_short_with_a_command_and_a_figure(page: Path) -> None:
    text = page.read_text()
    assert len(text.splitlines()) <= MAX_PAGE_LINES, page.name
    commands = [
        line
        for lang, body in FENCE.findall(text)
        if lang in ("", "console", "bash", "sh")
        for line in body.splitlines()
        if line.removeprefix("$ ").startswith("abrupt ")
    ]
    assert commands, f"{page.name}: no command to type"
    figures = re.findall(r"!\[[^\]]*\]\(([^)\s]+\.png)\)", text)
    expected = 0 if page.name in NO_FIGURE else 1
    assert len(figures) == expected, f"{page.name}: {len(figures)} figures"


def test_the_map_links_every_page() -> None:
    linked = {p.name for p in _map_pages()}
    assert len(linked) >= 12
    assert all((ROOT / "docs" / name).exists() for name in linked)
    assert set(NO_FIGURE) <= linked, "a NO_FIGURE entry names a page the map no longer links"


@pytest.mark.parametrize("doc", [ROOT / "README.md", *PAGES], ids=lambda p: p.name)
def test_every_relative_link_names_a_file_that_exists(doc: Path) -> None:
    text = re.sub(r"^```.*?^```", "", doc.read_text(), flags=re.S | re.M)
    missing = []
    for target in LINK.findall(text):
        if re.match(r"^[a-z]+:", target) or target.startswith("#"):
            continue
        if not (doc.parent / target.split("#")[0]).exists():
            missing.append(target)
    assert not missing, f"{doc.name}: links to missing files {missing}"
