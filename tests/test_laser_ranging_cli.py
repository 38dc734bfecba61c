"""``abrupt detect laser`` end to end on files in the ILRS formats (CRD v2, SINEX) and a CCSDS OEM a-priori.

Simulated LAGEOS-like ranges (full range model in the truth) are written as a CRD normal-point file, the
stations as SINEX (positions, velocities, eccentricities) and the a-priori orbit as OEM; the command must
read them back, stay quiet on a maneuver-free day, and name the station a SINEX file lacks.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from abrupt.cli.main import cli, main
from abrupt.model.orbit import propagate
from abrupt.model.tracking_measurements import earth_rotation_matrices
from abrupt.pipelines.laser_ranging import LASER_FORCE
from abrupt.readers.ephemeris import write_ephemeris
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.slr import SlrScenario, SlrSimulation, simulate_slr

C = 299_792_458.0
CDP = {"YARL": "7090", "GRZL": "7839", "HERL": "7840", "GODL": "7105"}


def write_crd(sim: SlrSimulation, path: Path) -> None:
    """One CRD v2 normal-point block per station pass, epochs at ground receive time (event 0)."""
    lines: list[str] = []
    meas = sim.measurements
    for name, rows in meas.groupby("station", sort=True):
        t = pd.to_datetime(rows["time_utc"]).reset_index(drop=True)
        brk = np.flatnonzero(np.diff(t.astype("int64").to_numpy()) > 1800e9) + 1
        for chunk in np.split(np.arange(len(t)), brk):
            r = rows.iloc[chunk]
            t0, t1 = t[chunk[0]], t[chunk[-1]]
            lines.append("H1 CRD  2 2024 03 01 00")
            lines.append(f"H2 {name:<10s} {CDP[name]} 01 01 4")
            lines.append("H3 lageos1 7603901 1155 08820 0 1")
            lines.append(f"H4 1 {t0:%Y %m %d %H %M %S} {t1:%Y %m %d %H %M %S} 0 0 0 0 1 0 2 0")
            lines.append("C0 0 532.000 std1")
            day0 = t0.normalize()
            for k, (_, row) in enumerate(r.iterrows()):
                sod = (pd.Timestamp(row["time_utc"]) - day0).total_seconds()
                if k == 0:
                    meteo = f"{row['pressure_hpa']:.2f} {row['temperature_k']:.2f} {100 * row['humidity']:.1f}"
                    lines.append(f"20 {sod:.3f} {meteo} 0")
                tof = 2.0 * row["range_m"] / C
                lines.append(f"11 {sod:.7f} {tof:.12f} std1 0 120 10 13.3 -1 -1 -1 -1 0")
            lines.append("H8")
    lines.append("H9")
    path.write_text("\n".join(lines) + "\n")


def write_sinex(sim: SlrSimulation, path: Path, drop: str | None = None) -> None:
    epoch = pd.Timestamp(sim.scenario.sinex_epoch)
    doy = f"{epoch:%y}:{epoch.day_of_year:03d}:00000"
    out = ["%=SNX 2.02 ABR 24:061:00000 ABR 24:061:00000 24:062:00000 L 00024 2 S E", "+SITE/ID"]
    for name, code in CDP.items():
        if name != drop:
            out.append(f" {code}  A 00000M000 L {name:<22s} 0 0 0.0 0 0 0.0 0.0")
    out += ["-SITE/ID", "+SITE/ECCENTRICITY"]
    for name, code in CDP.items():
        e = sim.sites[name].eccentricity_une_m
        out.append(f" {code}  A    1 L 00:000:00000 00:000:00000 UNE {e[0]:8.4f} {e[1]:8.4f} {e[2]:8.4f}")
    out += ["-SITE/ECCENTRICITY", "+SOLUTION/ESTIMATE"]
    k = 0
    for name, code in CDP.items():
        if name == drop:
            continue
        site = sim.sites[name]
        ref = pd.Timestamp(site.reference_epoch)  # each site's own reference epoch
        doy = f"{ref:%y}:{ref.day_of_year:03d}:{ref.hour * 3600 + ref.minute * 60 + ref.second:05d}"
        for axis, value in zip("XYZ", site.position_ecef_m, strict=True):
            k += 1
            out.append(f" {k:5d} STA{axis}   {code}  A    1 {doy} m    2 {value: .15E} 0.10000E-02")
        for axis, value in zip("XYZ", site.velocity_m_per_yr, strict=True):
            k += 1
            out.append(f" {k:5d} VEL{axis}   {code}  A    1 {doy} m/y  2 {value: .15E} 0.10000E-03")
    out += ["-SOLUTION/ESTIMATE", "%ENDSNX"]
    path.write_text("\n".join(out) + "\n")


def write_apriori(sim: SlrSimulation, path: Path, start_s: float = -600.0) -> None:
    """The true orbit, shifted by 50 m, in ITRF (as a CPF prediction would give it), written as OEM."""
    t = np.arange(start_s, sim.scenario.duration_days * 86400.0 + 600.0, 120.0)
    states = propagate(sim.x0, t[t >= 0], force=sim.force)
    back = propagate(sim.x0, np.array([0.0]), force=sim.force)
    states = np.vstack([np.repeat(back, int((t < 0).sum()), axis=0), states])
    states[t < 0, :3] += np.outer(t[t < 0], states[0, 3:])
    c_fi = earth_rotation_matrices(t, model="iers", epoch_utc=sim.epoch_utc)
    r = np.einsum("nij,nj->ni", c_fi, states[:, :3]) + 50.0
    v = np.einsum("nij,nj->ni", c_fi, states[:, 3:]) - np.cross([0.0, 0.0, 7.292115e-5], r)
    times = sim.epoch_utc + (t * 1e9).astype("timedelta64[ns]")
    write_ephemeris(Ephemeris("lageos1", times, r, v, "ITRF"), path, fmt="oem")


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    # the truth has the real-data force model (20×20 field, Sun, Moon, SRP) with 20 % more radiation
    # pressure than the command's a-priori C_R: the fitted SRP scale must absorb it
    truth = replace(LASER_FORCE, srp_coefficient=1.2 * LASER_FORCE.srp_coefficient)
    sim = simulate_slr(SlrScenario(duration_days=1.0, noise_m=0.003, force=truth), seed=21)
    d = tmp_path_factory.mktemp("laser")
    paths = {"crd": d / "lageos1.npt", "snx": d / "sites.snx", "oem": d / "apriori.oem", "bad_snx": d / "missing.snx"}
    paths["late_oem"] = d / "late.oem"
    write_crd(sim, paths["crd"])
    write_sinex(sim, paths["snx"])
    write_sinex(sim, paths["bad_snx"], drop="GRZL")
    write_apriori(sim, paths["oem"])
    write_apriori(sim, paths["late_oem"], start_s=6 * 3600.0)  # starts hours after the first range
    return paths


def test_detect_laser_reads_crd_sinex_and_oem_and_stays_quiet(files: dict[str, Path], tmp_path: Path) -> None:
    """Quiet on a maneuver-free day; the SRP scale absorbs the truth's 20 % more radiation pressure; the
    station time biases (there are none in the truth) come out near zero."""
    out = tmp_path / "events.csv"
    lines = files["crd"].read_text().splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("11 "))
    crd = tmp_path / "duplicated.npt"  # one normal point repeated: dropped, counted and printed
    crd.write_text("\n".join([*lines[: k + 1], lines[k], *lines[k + 1 :]]) + "\n")
    args = ["detect", "laser", str(crd), "--sinex", str(files["snx"]), "--apriori", str(files["oem"])]
    args += ["--out", str(out), "--catalog", str(tmp_path / "c.sqlite"), "--fit-out", str(tmp_path / "fit.json")]
    args += ["--time-biases"]
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    events = pd.read_csv(out)
    assert len(events) == 0
    assert "post-fit range RMS per station" in result.output
    assert "repaired: identical duplicated ranges dropped (1)" in result.output
    fit = pd.read_json(tmp_path / "fit.json", typ="series")
    assert fit["repairs"]["identical duplicated ranges dropped"] == 1
    assert max(fit["residual_rms_mm"].values()) < 3 * 3.0  # mm, against 3 mm normal points
    assert not math.isnan(float(next(iter(fit["range_bias_mm"].values()))))
    assert fit["scale_factors"]["srp_scale"] == pytest.approx(1.2, abs=0.1)
    biases = fit["time_bias_us"]
    assert len(biases) == len(CDP) - 1 and set(biases) < set(CDP.values())  # relative to the busiest station
    assert max(abs(v) for v in biases.values()) < 5.0  # µs; 3 mm at a few km/s of range rate is ~1 µs


def test_detect_laser_names_the_station_missing_from_sinex(files: dict[str, Path], tmp_path: Path) -> None:
    args = ["detect", "laser", str(files["crd"]), "--sinex", str(files["bad_snx"]), "--apriori", str(files["oem"])]
    args += ["--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")]
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2


def test_detect_laser_names_an_apriori_ephemeris_that_starts_after_the_ranges(
    files: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:

    args = ["detect", "laser", str(files["crd"]), "--sinex", str(files["snx"]), "--apriori", str(files["late_oem"])]
    args += ["--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")]
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "late.oem" in err and "does not cover" in err
    assert len(err.strip().splitlines()) == 1
