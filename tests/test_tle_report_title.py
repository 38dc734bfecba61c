"""The TLE report names the satellite it draws: the 3LE name line when the file has one, else the file.

Independent truth: the names are the ones written into the files here (a plain two-line history from
sgp4's exporter, and the same sets with a name line before each)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from abrupt.events import EVENT_COLUMNS
from abrupt.readers.tle import read_tle
from abrupt.report.tle import plot_tle_report, report_title
from test_tle_synthetic import synthetic_tle_text


def _three_line(text: str, name: str) -> str:
    """The two-line sets of ``text`` with ``name`` on a line before each."""
    lines = text.strip().splitlines()
    return "".join(f"{name}\n{a}\n{b}\n" for a, b in zip(lines[::2], lines[1::2], strict=True))


def test_a_plain_two_line_file_is_named_after_its_file(tmp_path: Path) -> None:
    text, _ = synthetic_tle_text(days=60.0, norad=99017)
    path = tmp_path / "kestrel-elements.tle"
    path.write_text(text)
    history = read_tle(path)
    assert history.name is None  # nothing in a two-line file names the satellite
    assert report_title(history, 2) == "kestrel-elements.tle (NORAD 99017): 2 maneuver(s)"


def test_a_name_line_names_the_satellite(tmp_path: Path) -> None:
    text, _ = synthetic_tle_text(days=60.0, norad=99017)
    path = tmp_path / "elements.tle"
    path.write_text(_three_line(text, "KESTREL 2"))
    assert report_title(read_tle(path), 0) == "KESTREL 2 (NORAD 99017): 0 maneuver(s)"


def test_the_drawn_figure_carries_the_title(tmp_path: Path) -> None:
    text, _ = synthetic_tle_text(days=60.0, norad=99017)
    path = tmp_path / "kestrel-elements.tle"
    path.write_text(text)
    out = plot_tle_report(read_tle(path), pd.DataFrame(columns=EVENT_COLUMNS), tmp_path / "report.svg")
    assert "kestrel-elements.tle (NORAD 99017): 0 maneuver(s)" in out.read_text()  # SVG keeps text as comments


def test_a_pseudonym_replaces_the_name_and_control_characters_are_escaped(tmp_path: Path) -> None:
    text, _ = synthetic_tle_text(days=60.0, norad=99017)
    path = tmp_path / "elements.tle"
    path.write_text(_three_line(text, "KESTREL 2"))
    history = read_tle(path)
    assert report_title(history, 1, name="bird-7") == "bird-7 (NORAD 99017): 1 maneuver(s)"
    assert "KESTREL" not in report_title(history, 1, name="bird-7")
    assert report_title(history, 1, name="x\x1b[31my") == "x\\x1b[31my (NORAD 99017): 1 maneuver(s)"
