"""Header-announced counts of SP3 files that the records do not match: read as found with a counted
repair naming both counts when the records are complete, an error with ``strict`` or when the file
stops in the middle of a record."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError
from abrupt.readers.sp3 import parse_sp3, read_sp3, write_sp3
from abrupt.series.ephemeris import Ephemeris

N = 12


def _ephemeris(sid: str, phase: float) -> Ephemeris:
    t = np.datetime64("2016-02-28T00:00:00", "ns") + np.arange(N) * np.timedelta64(120, "s")
    ang = phase + 2 * np.pi * np.arange(N) * 120.0 / 13500.0
    r = 12.27e6
    pos = np.column_stack([r * np.cos(ang), r * np.sin(ang), np.zeros(N)])
    vel = np.column_stack([-5700.0 * np.sin(ang), 5700.0 * np.cos(ang), np.zeros(N)])
    return Ephemeris(satellite=sid, times_utc=t, position_m=pos, velocity_mps=vel, frame="GCRF", source="synthetic")


def _write(tmp_path: Path) -> list[str]:
    path = tmp_path / "two.sp3"
    write_sp3([_ephemeris("L52", 0.0), _ephemeris("L51", 1.0)], path, version="c")
    return path.read_text().splitlines()


def _save(tmp_path: Path, lines: list[str], name: str) -> Path:
    out = tmp_path / name
    out.write_text("\n".join(lines) + "\n")
    return out


def _announce(lines: list[str], n: int) -> list[str]:
    head = lines[0]
    return [head[:32] + f"{n:7d}" + head[39:], *lines[1:]]


def test_one_epoch_more_announced_than_held_is_read_with_the_counts(tmp_path: Path) -> None:
    path = _save(tmp_path, _announce(_write(tmp_path), N + 1), "count.sp3")
    eph = read_sp3(path, "L52")
    assert eph.times_utc.size == N
    key = f"header announces {N + 1} epochs, the file holds {N} complete ones (read as found)"
    assert eph.repairs.counts[key] == 1
    with pytest.raises(InputError, match=rf"count.sp3:\d+: header announces {N + 1} epochs but the file holds {N}$"):
        read_sp3(path, "L52", strict=True)


def test_fewer_epochs_announced_than_held_is_read_with_the_counts(tmp_path: Path) -> None:
    lines = _announce(_write(tmp_path), N - 3)
    key = f"header announces {N - 3} epochs, the file holds {N} complete ones (read as found)"
    for name, text in (("more.sp3", lines), ("more-no-eof.sp3", [ln for ln in lines if ln != "EOF"])):
        content = parse_sp3(_save(tmp_path, text, name))
        assert all(e.times_utc.size == N for e in content.ephemerides.values())
        assert content.repairs.counts[key] == 3
    # without EOF the last epoch must be whole: one satellite's records short, or its last line cut
    body = [ln for ln in lines if ln != "EOF"]
    for name, text in (("short.sp3", body[:-2]), ("cut.sp3", [*body[:-1], body[-1][:50]])):
        with pytest.raises(InputError, match=rf"header announces {N - 3} epochs but the file holds {N}$"):
            parse_sp3(_save(tmp_path, text, name))


def test_a_file_cut_in_the_middle_of_its_last_record_stays_an_error(tmp_path: Path) -> None:
    body = [ln for ln in _write(tmp_path) if ln != "EOF"]
    # cut inside the z field: the record itself cannot be read (and the file is too short to skip it)
    inside = _save(tmp_path, _announce([*body[:-1], body[-1][:40]], N + 1), "inside.sp3")
    with pytest.raises(InputError, match=r"inside.sp3:\d+:41: velocity record truncated"):
        parse_sp3(inside)
    # cut after the z field: the numbers read, but the line is shorter than its kind: a truncated file
    after = _save(tmp_path, _announce([*body[:-1], body[-1][:50]], N + 1), "after.sp3")
    with pytest.raises(
        InputError, match=rf"header announces {N + 1} epochs but the file holds {N} \(truncated file\?\)"
    ):
        parse_sp3(after)


def test_a_last_epoch_missing_a_satellite_without_eof_stays_an_error(tmp_path: Path) -> None:
    lines = _announce(_write(tmp_path), N + 1)
    body = [ln for ln in lines if ln != "EOF"][:-1]  # last epoch holds one of the two satellites
    with pytest.raises(InputError, match=r"\(truncated file\?\)"):
        parse_sp3(_save(tmp_path, body, "short.sp3"))
    # the same records with allow_truncated: read, the missing epoch counted
    content = parse_sp3(_save(tmp_path, body, "short.sp3"), allow_truncated=True)
    assert content.repairs.counts["file truncated: announced epochs missing"] == 1


def test_satellite_count_that_the_list_does_not_match(tmp_path: Path) -> None:
    lines = _write(tmp_path)
    plus = next(i for i, ln in enumerate(lines) if ln.startswith("+"))
    lines[plus] = lines[plus][:1] + f"{3:5d}" + lines[plus][6:]
    path = _save(tmp_path, lines, "sats.sp3")
    content = parse_sp3(path)
    assert sorted(content.ephemerides) == ["L51", "L52"]
    assert content.repairs.counts["header announces 3 satellites but lists 2 (the list is used)"] == 1
    with pytest.raises(InputError, match=r"sats.sp3:3:4: header announces 3 satellites but lists 2"):
        parse_sp3(path, strict=True)


def test_inject_orbit_command_reports_the_counts_and_strict_refuses(tmp_path: Path) -> None:
    from click.testing import CliRunner

    import abrupt.cli.main  # noqa: F401  (registers the command groups)
    from abrupt.cli.groups import cli

    lines = _write(tmp_path)
    path = _save(tmp_path, _announce(lines, N + 1), "cli.sp3")
    args = ["inject", "orbit", str(path), "--satellite", "L52", "--time", "2016-02-28T00:10:00", "--dv-rtn", "0,0.01,0"]
    ok = CliRunner().invoke(cli, [*args, "--out", str(tmp_path / "out.sp3")])
    assert ok.exit_code == 0, ok.output
    assert f"header announces {N + 1} epochs, the file holds {N} complete ones (read as found): 1" in ok.output
    refused = CliRunner().invoke(cli, [*args, "--strict", "--out", str(tmp_path / "out2.sp3")])
    assert isinstance(refused.exception, InputError)
    assert f"cli.sp3:{len(lines)}: header announces {N + 1} epochs but the file holds {N}" in str(refused.exception)
