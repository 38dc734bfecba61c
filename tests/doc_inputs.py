"""Small stand-ins for the input files the docs name, for ``tests/test_doc_commands_run.py``.

A doc names its inputs as a user has them (``Sentinel-3A.tle``, ``ssas3a20...sp3``, ``STORE``,
``fleet.csv``). Each name maps to a maker that writes a SMALL file of the same kind into the test's
folder, from ``../shared/data`` where the kind is there (slices of its TLE histories, SP3 arcs, the
flight-like archive) and otherwise from abrupt's own simulators or the test suite's synthetic writers
(an ISS-like OEM, a meteor radar file, a CubeSat constellation, laser normal points with their
a-priori orbit). Every maker says in its first docstring line what it makes; the test prints it.
"""

from __future__ import annotations

import contextlib
import functools
import gzip
import io
import shutil
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.cli.main import main

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples" / "spacecraft"
S3A_SP3 = "ssas3a20.b18358.e19003.DG_.sp3"
#: Hours of the flight-like archive's first day the stand-ins keep (the docs inject at 05:00 and 07:00).
ARCHIVE_HOURS = 8

Maker = Callable[[Path, Path], None]


def run(*args: str) -> None:
    """Run an abrupt command quietly (its output captured); a non-zero exit is an error."""
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        try:
            main(["-q", *args])
        except SystemExit as exc:
            if exc.code not in (0, None):
                raise RuntimeError(f"making a doc input: `abrupt {' '.join(args)}` exited with {exc.code}") from None


def tle_years(name: str, years: tuple[str, ...] = ("16", "17")) -> Maker:
    def make(shared: Path, target: Path) -> None:
        lines = (shared / "tle" / name).read_text().splitlines(keepends=True)
        sets = [lines[i : i + 2] for i in range(0, len(lines) - 1, 2) if lines[i].startswith("1 ")]
        target.write_text("".join(a + b for a, b in sets if a[18:20] in years))

    make.__doc__ = f"{name} of ../shared/data/tle, the element sets of 20{'+20'.join(years)}"
    return make


def copy_shared(relative: str) -> Maker:
    def make(shared: Path, target: Path) -> None:
        shutil.copyfile(shared / relative, target)

    make.__doc__ = f"../shared/data/{relative}"
    return make


def example(name: str) -> Maker:
    def make(shared: Path, target: Path) -> None:
        shutil.copyfile(EXAMPLES / name, target)

    make.__doc__ = f"examples/spacecraft/{name}"
    return make


def _sp3_header(lines: list[str], first: int, epochs: int) -> list[str]:
    """The two header lines of an SP3-c file rewritten for a slice: start epoch, count, GPS week, MJD."""
    year, month, day, hour, minute, second = lines[first][3:31].split()
    t0 = pd.Timestamp(int(year), int(month), int(day), int(hour), int(minute)) + pd.Timedelta(seconds=float(second))
    week, sow = divmod((t0 - pd.Timestamp("1980-01-06")).total_seconds(), 7 * 86400.0)
    mjd = (t0 - pd.Timestamp("1858-11-17")).total_seconds() / 86400.0
    head1 = lines[0][:3] + lines[first][3:31] + f" {epochs:7d}" + lines[0][39:]
    head2 = f"## {int(week):4d} {sow:15.8f} {lines[1][24:38]} {int(mjd):5d} {mjd - int(mjd):15.13f}\n"
    return [head1, head2]


def sp3_slice(start: str | None = None, epochs: int = 240) -> Maker:
    def make(shared: Path, target: Path) -> None:
        lines = (shared / "sp3" / S3A_SP3).read_text().splitlines(keepends=True)
        starts = [i for i, line in enumerate(lines) if line.startswith("*")]
        k = 0
        if start is not None:
            t = pd.Timestamp(start)
            stamp = f"*  {t.year:4d} {t.month:2d} {t.day:2d} {t.hour:2d} {t.minute:2d}"
            k = next(j for j, i in enumerate(starts) if lines[i].startswith(stamp))
        first = starts[k]
        body = lines[first : starts[k + epochs]]
        target.write_text("".join(_sp3_header(lines, first, epochs) + lines[2 : starts[0]] + body) + "EOF\n")

    where = f"from {start}" if start else "from its start"
    make.__doc__ = f"the Sentinel-3A SP3 arc of ../shared/data/sp3, {epochs} epochs {where} (header rewritten)"
    return make


def archive_hours(hours: int = ARCHIVE_HOURS) -> Maker:
    def make(shared: Path, target: Path) -> None:
        src = shared / "flight-like" / "telemetry" / "KESTREL2_2026-03-10.csv.gz"
        stop = f"2026-03-10T{hours:02d}:"
        with gzip.open(src, "rt") as fh, gzip.open(target, "wt") as out:
            for line in fh:
                if line.startswith(stop):
                    break
                out.write(line)

    make.__doc__ = f"the flight-like archive of 2026-03-10, its first {hours} hours"
    return make


def folder(shared: Path, target: Path) -> None:
    """an empty folder (one the user made for the output)"""
    target.mkdir()


def store(shared: Path, target: Path) -> None:
    """an ingest store (pseudonym SC-A) of the flight-like archive's first hours"""
    archive = target.parent / f"_{target.name}_archive" / "KESTREL2_2026-03-10.csv.gz"
    archive.parent.mkdir()
    archive_hours()(shared, archive)
    run("ingest", str(archive), "--decoder", str(shared / "flight-like" / "decoder.csv"), "--store", str(target))


def telemetry(shared: Path, target: Path) -> None:
    """20 simulated minutes of thesis-spacecraft telemetry with two strikes (abrupt simulate attitude)"""
    run("simulate", "attitude", "--duration", "1200", "--random-strikes", "2", "--out", str(target))


def confounder_ranges(shared: Path, target: Path) -> None:
    """the ranges `simulate confounders --show-ranges` prints, the gyro bias steps narrowed"""
    with contextlib.redirect_stdout(io.StringIO()) as out:
        main(["simulate", "confounders", "--spacecraft", str(EXAMPLES / "kestrel.toml"), "--show-ranges"])
    text = "\n".join(
        "gyro_bias_deg_s = [0.005, 0.01]" if line.startswith("gyro_bias_deg_s") else line
        for line in out.getvalue().splitlines()
    )
    target.write_text(text + "\n")


def quiet_navigation(shared: Path, target: Path) -> None:
    """an event-free simulated arc of the same orbit (abrupt simulate orbit, another seed)"""
    run("simulate", "orbit", "--out", str(target), "--duration-s", "21600", "--seed", "2")


def iss_like_oem(shared: Path, target: Path) -> None:
    """a simulated ISS-like orbit (420 km, 51.6°) over the doc's hours, written as CCSDS OEM"""
    from abrupt.readers.ephemeris import read_ephemeris, write_ephemeris

    nav = target.parent / "_iss_nav.csv"
    run("simulate", "orbit", "--out", str(nav), "--duration-s", "7200", "--rate-hz", "0.0166666667",
        "--altitude-km", "420", "--inclination-deg", "51.6", "--epoch", "2023-02-15T10:00:00", "--sigma-pos-m", "0",
        "--sigma-vel-mps", "0")  # fmt: skip
    write_ephemeris(replace(read_ephemeris(nav), satellite="ISS"), target, fmt="oem-kvn")


def iss_like_oem_xml(shared: Path, target: Path) -> None:
    """8 h of the Sentinel-3A SP3 arc written as CCSDS OEM XML (the format NASA publishes the ISS in)"""
    from abrupt.readers.ephemeris import read_ephemeris, write_ephemeris

    sp3 = target.parent / "_oem_source.sp3"
    sp3_slice(epochs=480)(shared, sp3)
    write_ephemeris(read_ephemeris(sp3), target, fmt="oem-xml")


def lageos_sp3_gz(shared: Path, target: Path) -> None:
    """the LAGEOS-1 CPF of ../shared/data/tracking/ilrs-corpus written as a gzipped SP3 with id L52"""
    from abrupt.readers.ephemeris import read_ephemeris, write_ephemeris

    eph = read_ephemeris(shared / "tracking" / "ilrs-corpus" / "lageos1_cpf_180613_16401.hts")
    plain = target.parent / "_lageos.sp3"
    write_ephemeris(replace(eph, satellite="L52"), plain, fmt="sp3")
    target.write_bytes(gzip.compress(plain.read_bytes()))


def three_line_extract(shared: Path, target: Path) -> None:
    """a 3LE catalogue extract: two years of Sentinel-3A and of Jason-3 with name lines"""
    parts = []
    for name, years in (("Sentinel-3A", ("16", "17")), ("Jason-3", ("17", "18"))):
        two = target.parent / f"_{name}.tle"
        tle_years(f"{name}.tle", years)(shared, two)
        lines = two.read_text().splitlines()
        parts += [f"0 {name.upper()}\n{a}\n{b}\n" for a, b in zip(lines[0::2], lines[1::2], strict=True)]
    target.write_text("".join(parts))


def tle_folder(shared: Path, target: Path) -> None:
    """a folder of two TLE histories (two years each of Sentinel-3A and Jason-3)"""
    target.mkdir()
    tle_years("Sentinel-3A.tle")(shared, target / "Sentinel-3A.tle")
    tle_years("Jason-3.tle", ("17", "18"))(shared, target / "Jason-3.tle")


def catalogue_list(shared: Path, target: Path) -> None:
    """a list of TLE files, one a line (the two histories of the tle/ stand-in)"""
    folder = target.parent / "_catalogue"
    tle_folder(shared, folder)
    target.write_text("".join(f"_catalogue/{p.name}\n" for p in sorted(folder.glob("*.tle"))))


def fleet_manifest(shared: Path, target: Path) -> None:
    """a fleet manifest of two simulated spacecraft, 20 minutes of telemetry each (thesis spacecraft)"""
    rows = ["spacecraft,telemetry,spacecraft_file"]
    for k, name in enumerate(("sat-1", "sat-2")):
        tel = target.parent / name / "2026-01-01.parquet"
        tel.parent.mkdir()
        run("simulate", "attitude", "--duration", "1200", "--random-strikes", "1", "--seed", str(k + 1),
            "--out", str(tel))  # fmt: skip
        rows.append(f"{name},{name}/2026-01-01.parquet,{EXAMPLES / 'thesis.toml'}")
    target.write_text("\n".join(rows) + "\n")


def _constellation() -> object:
    from reproductions.density_constellation import simulate_constellation

    return simulate_constellation(6, days=8.0, seed=31, storm_start_day=4.0, step_s=600.0)


def cubesat_folder(shared: Path, target: Path) -> None:
    """six simulated CubeSats' TLE histories over eight days (the density tests' constellation)"""
    sim = _constellation()
    target.mkdir()
    for name, text in sim.tle_texts.items():  # type: ignore[attr-defined]
        (target / f"{name}.tle").write_text(text)


def platforms(shared: Path, target: Path) -> None:
    """the platforms file of the simulated CubeSats (shape class, face areas, mass)"""
    sim = _constellation()
    frame = sim.platforms.drop(columns=["object"]).rename(columns={"norad_id": "object"})  # type: ignore[attr-defined]
    frame.to_csv(target, index=False)


def radar(shared: Path, target: Path) -> None:
    """simulated meteor head echoes of 80 meteoroids (abrupt.density.meteors.simulate_head_echoes)"""
    from abrupt.density.meteors import simulate_head_echoes

    simulate_head_echoes(80, seed=1).echoes.to_csv(target, index=False)


def ordem_size(shared: Path, target: Path) -> None:
    """an ORDEM 3.1 spacecraft-mode size table in the output's layout (synthetic values)"""
    from test_rates_tables import ORDEM_SIZE

    target.write_text(ORDEM_SIZE)


def ordem_igloo(shared: Path, target: Path) -> None:
    """an ORDEM 3.1 igloo table in the output's layout (synthetic values)"""
    from test_rates_tables import ORDEM_IGLOO

    target.write_text(ORDEM_IGLOO)


@functools.cache
def _slr_simulation() -> object:
    """One simulated day of LAGEOS-1 laser ranging for the session (it takes half a minute of CPU)."""
    from abrupt.simulate.slr import SlrScenario, simulate_slr

    return simulate_slr(SlrScenario(duration_days=1.0, noise_m=0.003), seed=21)


@functools.cache
def _slr_simulation_real_forces() -> object:
    """The same day as the command sees it by default: its forces in the truth (EGM2008 20×20, Sun, Moon,
    radiation pressure; a J2-only truth is metres a day from the command's richer model at LAGEOS height)
    and the stations at their ILRS SLRF2014 coordinates, which the command uses without ``--sinex``
    (the approximate sites of the simulator are 0.7-12 m from them)."""
    from abrupt.pipelines.laser_ranging import LASER_FORCE, sites_from_sinex
    from abrupt.readers.sinex import bundled_ilrs_sinex, read_sinex
    from abrupt.simulate.slr import SlrScenario, simulate_slr
    from test_laser_ranging_cli import CDP

    scenario = SlrScenario(duration_days=1.0, noise_m=0.003, force=LASER_FORCE)
    start = np.datetime64(scenario.start_utc)
    by_code = sites_from_sinex(read_sinex(str(bundled_ilrs_sinex())), list(CDP.values()), start)
    sites = {name: replace(by_code[code], name=name) for name, code in CDP.items()}
    return simulate_slr(scenario, seed=21, sites=sites)


def _slr_campaign(folder: Path) -> dict[str, Path]:
    """Simulated LAGEOS-1 normal points of one day (CRD), the stations (SINEX) and an a-priori orbit."""
    from test_laser_ranging_cli import write_apriori, write_crd, write_sinex

    paths = {"crd": folder / "lageos1.npt", "apriori": folder / "lageos1.cpf", "sinex": folder / "ilrs.snx"}
    if not paths["crd"].exists():
        sim = _slr_simulation_real_forces()
        write_crd(sim, paths["crd"])  # type: ignore[arg-type]
        write_apriori(sim, paths["apriori"])  # type: ignore[arg-type]
        write_sinex(sim, paths["sinex"])  # type: ignore[arg-type]
    return paths


def slr(kind: str) -> Maker:
    def make(shared: Path, target: Path) -> None:
        made = _slr_campaign(target.parent)[kind]
        assert made == target, (made, target)

    make.__doc__ = {
        "crd": "a simulated day of LAGEOS-1 normal points from four ILRS stations (CRD v2)",
        "apriori": "the simulated orbit shifted by 50 m in ITRF (the a-priori a CPF gives), as OEM",
        "sinex": "the simulated stations' positions and velocities (SINEX)",
    }[kind]
    return make


def crd_gz(shared: Path, target: Path) -> None:
    """the simulated day of LAGEOS-1 normal points (CRD v2), gzipped"""
    from test_laser_ranging_cli import write_crd

    plain = target.parent / "_passes.npt"
    write_crd(_slr_simulation(), plain)  # type: ignore[arg-type]
    target.write_bytes(gzip.compress(plain.read_bytes()))


def slr_setup(shared: Path, target: Path) -> None:
    """an Orekit set-up for those normal points: the simulation's initial state, force model and four stations"""
    from abrupt.simulate.slr import DEFAULT_SITES

    sim = _slr_simulation()
    force = sim.scenario.force  # type: ignore[attr-defined]
    degree = max(force.zonal_degree, force.gravity_degree)  # the simulation's field (J2), not a 20x20 one
    lines = [f"orbit.date = {np.datetime_as_string(sim.epoch_utc, unit='ms')}", "inertial.frame = EME2000"]  # type: ignore[attr-defined]
    for key, value in zip(("px", "py", "pz", "vx", "vy", "vz"), sim.x0, strict=True):  # type: ignore[attr-defined]
        lines.append(f"orbit.cartesian.{key} = {value:.3f}")
    lines += [f"central.body.degree = {degree}", f"central.body.order = {degree}"]
    lines += [f"third.body.sun = {str(force.sun).lower()}", f"third.body.moon = {str(force.moon).lower()}"]
    for k, (name, lat, lon, height, _, _) in enumerate(DEFAULT_SITES):
        lines += [
            f"ground.station.name [{k}] = {name}",
            f"ground.station.latitude [{k}] = {lat}",
            f"ground.station.longitude [{k}] = {lon}",
            f"ground.station.altitude [{k}] = {height}",
            f"ground.station.range.sigma [{k}] = 1.0",
            f"ground.station.range.tropospheric.correction [{k}] = true",
        ]
    target.write_text("\n".join(lines) + "\n")


def other_detector_events(shared: Path, target: Path) -> None:
    """Two strikes of another detector (SC-B, March 2026) in the event schema, orbit-frame ΔH given."""
    target.write_text(
        "spacecraft,kind,detector,time_utc,dH_Nms,false_alarms_per_day,dH_O_r_Nms,dH_O_t_Nms,dH_O_n_Nms\n"
        "SC-B,strike,other.glr,2026-03-10T01:02:03Z,0.05,1,0.03,0.0,0.04\n"
        "SC-B,strike,other.glr,2026-03-12T11:00:00Z,0.13,1,0.0,0.12,0.05\n"
    )


def exposure_days(shared: Path, target: Path) -> None:
    """A per-day exposure table of three March 2026 days: analysed fraction, efficiency and orbit."""
    target.write_text(
        "day,analysed_fraction,dH90_Nms,efficiency_slope,altitude_km,inclination_deg,false_alarms_per_day\n"
        "2026-03-10,0.93,0.02,4,700,98.2,1\n"
        "2026-03-11,0.88,0.02,4,700,98.2,1\n"
        "2026-03-12,0.91,0.025,4,700,98.2,1\n"
    )
