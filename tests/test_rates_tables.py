"""Flux-table format and ORDEM importer: round trip, and a clear error for every malformed table."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import ConfigError, InputError
from abrupt.rates.ordem import import_ordem, read_ordem_igloo, read_ordem_size
from abrupt.rates.tables import nasa90_table, read_flux_table, write_flux_table

SIZE_HEADER = "size_m,density_class,cumulative_flux_m2_yr,sigma_m2_yr\n"
DIR_HEADER = "speed_kms_lo,speed_kms_hi,azimuth_deg_lo,azimuth_deg_hi,elevation_deg_lo,elevation_deg_hi,flux_m2_yr\n"
GOOD_SIZE = SIZE_HEADER + "1e-4,medium,10,1\n1e-3,medium,0.1,0.01\n1e-4,high,2,0.5\n1e-3,high,0.02,0.005\n"
GOOD_DIR = DIR_HEADER + "9,10,-10,0,0,0,3\n10,11,0,10,0,0,1\n"


def _write(tmp_path: Path, size: str = GOOD_SIZE, direction: str = GOOD_DIR, extra: str = "") -> Path:
    (tmp_path / "s.csv").write_text(size)
    (tmp_path / "d.csv").write_text(direction)
    manifest = tmp_path / "t.toml"
    manifest.write_text(
        f'format = "abrupt-flux-table/1"\nname = "test"\n{extra}size_table = "s.csv"\ndirection_table = "d.csv"\n'
    )
    return manifest


def test_documented_format_reads_and_round_trips(tmp_path: Path) -> None:
    t = read_flux_table(_write(tmp_path))
    assert t.classes == ("medium", "high")
    assert t.flux_above(1e-4) == pytest.approx(12.0)
    assert t.directions.weight.tolist() == pytest.approx([0.75, 0.25])
    assert t.directions.speed_lo_mps[0] == 9000.0
    again = read_flux_table(write_flux_table(t, tmp_path / "out" / "copy.toml"))
    assert np.allclose(again.cumulative_flux, t.cumulative_flux)
    assert np.allclose(again.directions.azimuth_lo_rad, t.directions.azimuth_lo_rad)
    nasa = nasa90_table(550e3, 28.5, 2020.0)
    back = read_flux_table(write_flux_table(nasa, tmp_path / "nasa.toml"))
    assert back.flux_above(1e-3) == pytest.approx(nasa.flux_above(1e-3), rel=1e-6)


def test_tumbling_convention_is_converted_to_cross_section(tmp_path: Path) -> None:
    t = read_flux_table(_write(tmp_path, extra='flux_convention = "tumbling"\n'))
    assert t.flux_above(1e-4) == pytest.approx(48.0)


def test_bounds_shift_flux_by_sigma_and_stay_non_negative(tmp_path: Path) -> None:
    t = read_flux_table(_write(tmp_path))
    assert t.bounded(2).flux_above(1e-4) == pytest.approx(12.0 + 2 * 1.5)
    assert t.bounded(-2).flux_above(1e-4) == pytest.approx(8.0 + 1.0)
    assert np.all(t.bounded(-50).cumulative_flux >= 0)


@pytest.mark.parametrize(
    "size,match,line",
    [
        ("", "empty flux table", None),
        (SIZE_HEADER, "header but no rows", None),
        (SIZE_HEADER + "-1e-4,medium,10,1\n1e-3,medium,1,0\n", "size must be positive", 2),
        (SIZE_HEADER + "1e-4,medium,10,1\n1e-4,medium,1,0\n", "duplicate size", 3),
        (SIZE_HEADER + "1e-3,medium,10,1\n1e-4,medium,20,0\n", "out of order", 3),
        (SIZE_HEADER + "1e-4,medium,1,1\n1e-3,medium,2,0\n", "increases with size", 3),
        (
            SIZE_HEADER + "1e-4,medium,10,1\n1e-3,medium,1,0\n1e-4,high,1,0\n2e-3,high,0.1,0\n",
            "different size grid",
            4,
        ),
        (SIZE_HEADER + "1e-4,steel,10,1\n1e-3,steel,1,0\n", "unknown density class", 2),
        (SIZE_HEADER + "1e-4,medium,ten,1\n", "not a number", 2),
        (SIZE_HEADER + "1e-4,medium,10\n", "expected 4 fields", 2),
        (SIZE_HEADER + "1e-4,medium,10,-1\n1e-3,medium,1,0\n", "sigma must not be negative", 2),
        ("size,class,flux\n1,medium,1\n", "missing column", 1),
    ],
)
def test_malformed_size_tables_are_errors_naming_the_line(
    tmp_path: Path, size: str, match: str, line: int | None
) -> None:
    with pytest.raises(InputError, match=match) as info:
        read_flux_table(_write(tmp_path, size=size))
    assert "s.csv" in str(info.value)
    assert info.value.line == line


@pytest.mark.parametrize(
    "direction,match",
    [
        (DIR_HEADER, "header but no rows"),
        (DIR_HEADER + "11,10,0,10,0,0,1\n", "speed_kms_lo > speed_kms_hi"),
        (DIR_HEADER + "9000,10000,0,10,0,0,1\n", "units must be km/s"),
        (DIR_HEADER + "9,10,0,10,-95,0,1\n", "elevation"),
        (DIR_HEADER + "9,10,0,10,0,0,0\n", "zero total flux"),
        (DIR_HEADER + "9,10,0,10,0,0,-1\n", "must not be negative"),
    ],
)
def test_malformed_direction_tables_are_errors(tmp_path: Path, direction: str, match: str) -> None:
    with pytest.raises(InputError, match=match):
        read_flux_table(_write(tmp_path, direction=direction))


def test_manifest_errors(tmp_path: Path) -> None:
    m = _write(tmp_path)
    m.write_text('format = "other"\nsize_table = "s.csv"\ndirection_table = "d.csv"\n')
    with pytest.raises(ConfigError, match="format"):
        read_flux_table(m)
    m.write_text('format = "abrupt-flux-table/1"\nsize_table = "s.csv"\n')
    with pytest.raises(ConfigError, match="direction_table"):
        read_flux_table(m)
    with pytest.raises(ConfigError, match="atmosphere"):
        read_flux_table(_write(tmp_path, extra="altitude_km = 80.0\n"))


ORDEM_SIZE = """ORDEM 3.1 spacecraft-mode output (synthetic layout for the test)
! population fluxes, #/m2/yr, cumulative
Size(m)   Intacts   NaK   LowDensity  MedDensity  HighDensity  Total  Total_Upper  Total_Lower
1.0E-05   1e-6  0.02  5.0  50.0  10.0  65.0  80.0  50.0
1.0E-04   1e-6  0.02  0.5  5.0   1.0   6.5   8.0   5.0
1.0E-03   1e-6  0.01  0.01 0.05  0.02  0.09  0.12  0.06
1.0E-02   1e-6  1e-4  1e-4 5e-4  2e-4  9e-4  1.2e-3 6e-4
"""
ORDEM_IGLOO = """# igloo flux, spacecraft mode
Azimuth(deg) Elevation(deg) Velocity(km/s) Flux(#/m2/yr)
-5 0 9.5 4.0
5 0 9.5 4.0
15 0 12.5 2.0
-15 10 12.5 0.0
"""


def test_ordem_importer_reads_populations_bounds_and_igloo(tmp_path: Path) -> None:
    (tmp_path / "size.out").write_text(ORDEM_SIZE)
    (tmp_path / "igloo.out").write_text(ORDEM_IGLOO)
    sizes, classes, flux, sigma = read_ordem_size(tmp_path / "size.out")
    assert classes == ("high", "nak", "low", "medium")  # intacts counted with high density
    assert sizes.tolist() == pytest.approx([1e-5, 1e-4, 1e-3, 1e-2])
    assert flux.sum(axis=0).tolist() == pytest.approx([65.020001, 6.520001, 0.090001, 9.01e-4])
    # (upper - lower)/4 = 7.5 shared by flux fraction
    assert sigma[:, 0].sum() == pytest.approx(7.5)
    bins = read_ordem_igloo(tmp_path / "igloo.out")
    assert bins.weight.tolist() == pytest.approx([0.4, 0.4, 0.2])
    assert bins.speed_lo_mps.tolist() == pytest.approx([8000.0, 8000.0, 11000.0])
    table = import_ordem(tmp_path / "size.out", tmp_path / "igloo.out", altitude_km=700)
    assert table.flux_above(1e-4) == pytest.approx(6.520001)


@pytest.mark.parametrize(
    "text,match",
    [
        ("", "empty table"),
        ("1 2 3\n", "numbers before any header"),
        ("Size(m) Total\n1e-4 2\n1e-3 3\n", "increases with size"),
        ("Size(m) Total\n-1e-4 2\n1e-3 1\n", "size must be positive"),
        ("Size(m) Total\n1e-4 2\n1e-4 1\n", "duplicate size"),
        ("Size(m) Total\n1e-4 2 5\n", "expected 2 values"),
        ("Size(m) Speed\n1e-4 2\n", "no flux column"),
    ],
)
def test_malformed_ordem_files_are_errors(tmp_path: Path, text: str, match: str) -> None:
    p = tmp_path / "bad.out"
    p.write_text(text)
    with pytest.raises(InputError, match=match):
        read_ordem_size(p)
