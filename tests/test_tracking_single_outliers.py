"""A single tracking record that disagrees with both neighbours is a counted outlier, never a maneuver."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from abrupt.cli.main import main


def _simulate(folder: Path, dv_mps: float) -> tuple[Path, Path]:
    aer, setup = folder / "t.aer", folder / "setup.txt"
    main(["-q", "simulate", "tracking", "--dv", str(dv_mps), "--out", str(aer), "--setup-out", str(setup)])
    return aer, setup


def _offset_range(aer: Path, index: int, offset_km: float) -> None:
    """Move the ``index``-th RANGE record by ``offset_km`` (the .aer file holds ranges in km)."""
    lines = aer.read_text().splitlines()
    k = [i for i, line in enumerate(lines) if line.split()[1] == "RANGE"][index]
    time, kind, station, value = lines[k].split()
    lines[k] = f"{time}   {kind}   {station}   {float(value) + offset_km:.6f}"
    aer.write_text("\n".join(lines) + "\n")


def _detect(folder: Path, aer: Path, setup: Path, capsys: pytest.CaptureFixture[str]) -> tuple[pd.DataFrame, str]:
    main(
        [
            "detect",
            "tracking",
            str(aer),
            "--setup",
            str(setup),
            "--out",
            str(folder / "e.csv"),
            "--catalog",
            str(folder / "c.sqlite"),
        ]
    )
    return pd.read_csv(folder / "e.csv"), capsys.readouterr().err


@pytest.mark.parametrize("offset_km", [0.05, 10.0])  # 10 and 2000 stated sigmas (5 m)
def test_one_bad_range_is_removed_and_counted_not_a_maneuver(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], offset_km: float
) -> None:
    aer, setup = _simulate(tmp_path, 0.0)
    _offset_range(aer, 200, offset_km)
    events, err = _detect(tmp_path, aer, setup, capsys)
    assert events.empty
    assert "single-record outliers (disagree with both neighbours) removed: 1" in err


def test_a_maneuver_keeps_its_records_and_is_found(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    aer, setup = _simulate(tmp_path, 1.0)
    events, err = _detect(tmp_path, aer, setup, capsys)
    assert "outliers" not in err
    assert (events["kind"] == "maneuver").sum() >= 1
