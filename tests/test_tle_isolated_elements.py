"""A TLE set with one field in another unit (inclination or node in radians, eccentricity ×10) departs from
both neighbours: it is dropped and counted, never a manoeuvre; a day of year beyond 366 is a malformed set.
An element that changes and stays changed (a real manoeuvre) keeps every set."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pytest

from abrupt.readers.tle import read_tle, tle_checksum
from abrupt.readers.tle_checks import TLE_ISOLATED_ELEMENTS
from abrupt.simulate.tle_catalogue import write_catalogue


def _sets(tmp_path: Path) -> list[list[str]]:
    (path,) = write_catalogue(tmp_path / "sim", 1, years=0.3, seed=1)
    lines = path.read_text().splitlines()
    return [lines[i : i + 2] for i, line in enumerate(lines) if line.startswith("1 ")]


def _field(line: str, start: int, text: str) -> str:
    line = line[:start] + text + line[start + len(text) :]
    return line[:68] + str(tle_checksum(line))


def _write(tmp_path: Path, sets: list[list[str]]) -> Path:
    path = tmp_path / "h.tle"
    path.write_text("\n".join(line for s in sets for line in s) + "\n")
    return path


def _degrees_to_radians(start: int) -> Callable[[list[str]], list[str]]:
    return lambda s: [s[0], _field(s[1], start, f"{math.radians(float(s[1][start : start + 8])):8.4f}")]


def _eccentricity_x10(s: list[str]) -> list[str]:
    return [s[0], _field(s[1], 26, f"{int(s[1][26:33]) * 10:07d}")]


@pytest.mark.parametrize(
    "damage", [_degrees_to_radians(8), _degrees_to_radians(17), _eccentricity_x10], ids=["inclination", "node", "ecc"]
)
def test_one_set_with_a_field_in_another_unit_is_dropped_and_counted(
    tmp_path: Path, damage: Callable[[list[str]], list[str]]
) -> None:
    sets = _sets(tmp_path)
    clean = read_tle(_write(tmp_path, sets))
    assert clean.repairs.as_dict().get(TLE_ISOLATED_ELEMENTS, 0) == 0
    k = len(sets) // 2
    sets[k] = damage(sets[k])
    history = read_tle(_write(tmp_path, sets))
    assert history.repairs.as_dict()[TLE_ISOLATED_ELEMENTS] == 1
    assert len(history.satrecs) == len(clean.satrecs) - 1
    gone = set(clean.elements["epoch_utc"]) - set(history.elements["epoch_utc"])
    assert gone == {clean.elements["epoch_utc"].iloc[k]}  # the damaged set is the one dropped


def test_an_inclination_that_changes_and_stays_keeps_every_set(tmp_path: Path) -> None:
    sets = _sets(tmp_path)
    k = len(sets) // 2
    for s in sets[k:]:
        s[1] = _field(s[1], 8, f"{float(s[1][8:16]) + 2.0:8.4f}")
    history = read_tle(_write(tmp_path, sets))
    assert history.repairs.as_dict().get(TLE_ISOLATED_ELEMENTS, 0) == 0
    assert len(history.satrecs) == len(sets)


def test_a_day_of_year_beyond_366_is_a_malformed_set_named_by_line_and_column(tmp_path: Path) -> None:
    sets = _sets(tmp_path)
    k = len(sets) // 2
    sets[k] = [_field(sets[k][0], 20, "400.50000000"), sets[k][1]]
    history = read_tle(_write(tmp_path, sets))
    assert len(history.satrecs) == len(sets) - 1
    assert any(f":{2 * k + 1}:21: epoch day of year 400.5" in str(e) for e in history.skipped)


def test_a_bad_set_just_before_a_plane_change_is_the_only_one_dropped(tmp_path: Path) -> None:
    """A cross-tagged set (another object's inclination and eccentricity) just before a real 1.7° plane
    change makes the last good set before the change look isolated too (its neighbours, the bad set and the
    first set after the change, agree); compared again once the bad set is gone, it is kept."""
    sets = _sets(tmp_path)
    k = len(sets) // 2
    for s in sets[k:]:
        s[1] = _field(s[1], 8, f"{float(s[1][8:16]) + 1.7:8.4f}")
    bad = sets[k - 2][1]
    bad = _field(bad, 8, f"{float(bad[8:16]) + 1.69:8.4f}")
    sets[k - 2] = [sets[k - 2][0], _field(bad, 26, "0200000")]
    clean = read_tle(_write(tmp_path, [s for j, s in enumerate(sets) if j != k - 2]))
    history = read_tle(_write(tmp_path, sets))
    assert history.repairs.as_dict()[TLE_ISOLATED_ELEMENTS] == 1
    assert list(history.elements["epoch_utc"]) == list(clean.elements["epoch_utc"])
