"""Only an Earth orbit becomes a result: the physical envelope every orbit file passes at the reader's door.

Each case writes a simulated orbit (two-body + J2 truth, 60 s, mm-level noise: the independent truth)
in a real format inside the test's folder, damages it as a careless producer would, and reads it with
:func:`abrupt.readers.ephemeris.read_ephemeris`: the damage is refused naming the envelope it breaks, or
repaired and counted so that what is read equals the undamaged truth.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import abrupt.cli.main  # noqa: F401  (registers the command groups)
from abrupt.catalog import Catalog
from abrupt.cli.groups import cli
from abrupt.errors import InputError
from abrupt.model.frames import gcrf_to_itrf
from abrupt.model.orbit import ForceModel
from abrupt.pipelines.orbit import detect_orbit
from abrupt.pipelines.orbit_blocks import bridge_limit_s, data_arcs
from abrupt.pipelines.orbit_product import detect_orbit_product
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.readers.oem import write_oem
from abrupt.readers.orbit_envelope import (
    OUTLIER_REPAIR,
    ZERO_VELOCITY_REPAIR,
    check_orbit_envelope,
    power_of_ten_repair,
    single_epoch_outliers,
)
from abrupt.readers.sp3 import write_sp3
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.orbit import OrbitSimulationConfig, inject_impulse, simulate_orbit

HOURS = 6.0


def _truth(altitude_km: float = 1336.0, sigma_pos_m: float = 0.002, eccentricity: float = 0.0) -> Ephemeris:
    cfg = OrbitSimulationConfig(
        altitude_m=altitude_km * 1e3,
        eccentricity=eccentricity,
        inclination_deg=66.0,
        duration_s=HOURS * 3600.0,
        rate_hz=1 / 60,
        sigma_pos_m=sigma_pos_m,
        sigma_vel_mps=sigma_pos_m / 100,
        epoch_utc="2008-08-30T21:00:00",
        forces=ForceModel(zonal_degree=2),
        seed=3,
    )
    return simulate_orbit(cfg).ephemeris("L27")


def _itrf(eph: Ephemeris) -> Ephemeris:
    r, v = gcrf_to_itrf(eph.times_utc, eph.position_m, eph.velocity_mps)
    return replace(eph, position_m=r, velocity_mps=v, frame="ITRF")


def _refused(path: Path, envelope: str) -> str:
    with pytest.raises(InputError) as info:
        read_ephemeris(path)
    message = str(info.value)
    assert "\n" not in message and str(path) in message
    assert f"outside the orbit envelope ({envelope})" in message
    return message


# ------------------------------------------------------------------------------------------ unmutated


@pytest.mark.parametrize("fmt", ["sp3", "oem", "csv"])
def test_the_undamaged_orbit_passes_in_every_format(fmt: str, tmp_path: Path) -> None:
    eph = _truth()
    path = tmp_path / f"orbit.{fmt}"
    {
        "sp3": lambda: write_sp3(eph, path),
        "oem": lambda: write_oem(eph, path),
        "csv": lambda: write_navigation_csv(eph, path),
    }[fmt]()
    back = read_ephemeris(path)
    assert len(back) == len(eph) and back.repairs.total == 0
    np.testing.assert_allclose(back.position_m, eph.position_m, atol=1e-3)


# ------------------------------------------------------------------------------------------ velocities


def test_oem_velocities_written_in_m_per_s_are_rescaled_and_counted(tmp_path: Path) -> None:
    """OEM states are km and km/s; velocities written in m/s (1000x too large) with intact positions."""
    eph = _truth()
    path = tmp_path / "m_per_s.oem"
    write_oem(replace(eph, velocity_mps=eph.velocity_mps * 1e3), path)
    back = read_ephemeris(path)
    assert back.repairs.counts[power_of_ten_repair(-3)] == len(eph)
    np.testing.assert_allclose(back.velocity_mps, eph.velocity_mps, rtol=1e-9, atol=1e-6)


def test_navigation_csv_velocities_in_km_per_s_are_rescaled_and_counted(tmp_path: Path) -> None:
    eph = _truth()
    path = tmp_path / "km_per_s.csv"
    write_navigation_csv(replace(eph, velocity_mps=eph.velocity_mps / 1e3), path)
    back = read_ephemeris(path)
    assert back.repairs.counts[power_of_ten_repair(3)] == len(eph)
    # the CSV keeps 6 decimals of the km/s values written: 1 mm/s once rescaled
    np.testing.assert_allclose(back.velocity_mps, eph.velocity_mps, rtol=0, atol=1e-3)


@pytest.mark.parametrize("fmt", ["oem", "csv"])
def test_all_zero_velocities_are_refused(fmt: str, tmp_path: Path) -> None:
    eph = replace(_truth(), velocity_mps=np.zeros((len(_truth()), 3)))
    path = tmp_path / f"zero.{fmt}"
    (write_oem if fmt == "oem" else write_navigation_csv)(eph, path)
    assert "every velocity is zero" in _refused(path, "velocity = derivative of position")


def test_one_zero_velocity_removes_its_epoch_and_is_counted(tmp_path: Path) -> None:
    eph = _truth()
    vel = eph.velocity_mps.copy()
    vel[100] = 0.0
    path = tmp_path / "one_zero.csv"
    write_navigation_csv(replace(eph, velocity_mps=vel), path)
    back = read_ephemeris(path)
    assert back.repairs.counts[ZERO_VELOCITY_REPAIR] == 1
    assert len(back) == len(eph) - 1 and eph.times_utc[100] not in back.times_utc


def test_velocities_halved_are_refused_not_repaired(tmp_path: Path) -> None:
    eph = _truth()
    path = tmp_path / "halved.csv"
    write_navigation_csv(replace(eph, velocity_mps=eph.velocity_mps * 0.5), path)
    assert "2 times the velocities" in _refused(path, "velocity = derivative of position")


# ------------------------------------------------------------------------------------------ scale, frame


def test_an_sp3_scaled_by_one_and_a_half_is_refused(tmp_path: Path) -> None:
    """Positions and velocities x1.5: kinematically consistent, but faster than escape at that radius."""
    eph = _itrf(_truth())
    path = tmp_path / "scaled.sp3"
    write_sp3(replace(eph, position_m=eph.position_m * 1.5, velocity_mps=eph.velocity_mps * 1.5), path)
    assert "above the escape speed" in _refused(path, "speed below escape")


def test_a_bound_orbit_scaled_by_one_point_one_is_refused_by_its_dynamics(tmp_path: Path) -> None:
    """x1.1 stays bound, but the accelerations it implies are 1.1³ = 1.33 times gravity at its radius."""
    eph = _truth()
    path = tmp_path / "scaled.csv"
    write_navigation_csv(replace(eph, position_m=eph.position_m * 1.1, velocity_mps=eph.velocity_mps * 1.1), path)
    _refused(path, "dynamics of the stated frame")


def test_itrf_data_labelled_j2000_is_refused_naming_the_frame_that_fits(tmp_path: Path) -> None:
    eph = _itrf(_truth())
    path = tmp_path / "mislabelled.oem"
    write_oem(replace(eph, frame="GCRF"), path)  # Earth-fixed states under an inertial label
    message = _refused(path, "dynamics of the stated frame")
    assert "they fit Earth-fixed (ITRF) data" in message


def test_the_same_itrf_data_labelled_itrf_passes(tmp_path: Path) -> None:
    eph = _itrf(_truth())
    path = tmp_path / "itrf.sp3"
    write_sp3(eph, path)
    assert len(read_ephemeris(path)) == len(eph)


# ------------------------------------------------------------------------------------------ radius, epochs


def test_positions_below_the_surface_are_refused(tmp_path: Path) -> None:
    eph = _truth()
    path = tmp_path / "low.csv"
    write_navigation_csv(replace(eph, position_m=eph.position_m * 0.8), path)  # 7714 km -> 6171 km
    assert "below the surface" in _refused(path, "radius above the Earth's surface")


def test_positions_beyond_the_moon_are_refused(tmp_path: Path) -> None:
    eph = _truth()
    path = tmp_path / "far.csv"
    write_navigation_csv(replace(eph, position_m=eph.position_m * 100.0), path)
    _refused(path, "radius below the Moon's distance")


def test_epochs_decades_in_the_future_are_refused(tmp_path: Path) -> None:
    eph = _truth()
    path = tmp_path / "future.oem"
    write_oem(replace(eph, times_utc=eph.times_utc + np.timedelta64(48 * 365, "D")), path)  # 2056
    assert "days after today" in _refused(path, "epochs not in the future")


def test_a_prediction_a_week_ahead_is_accepted() -> None:
    eph = _truth()
    now = eph.times_utc[0] - np.timedelta64(7, "D")
    assert len(check_orbit_envelope(eph, now_utc=now)) == len(eph)


# ------------------------------------------------------------------------------------------ outliers


@pytest.mark.parametrize("offset_m", [50.0, 1e3, 1e4])
def test_one_bad_record_is_removed_and_counted(offset_m: float, tmp_path: Path) -> None:
    """A 50 m step in one record, or one epoch 1-10 km off: that epoch only is removed, counted."""
    eph = _truth()
    k = 150
    bad = eph.position_m.copy()
    bad[k] += offset_m * np.array([0.6, -0.48, 0.64])
    path = tmp_path / "outlier.sp3"
    write_sp3(replace(eph, position_m=bad), path)
    back = read_ephemeris(path)
    assert back.repairs.counts[OUTLIER_REPAIR] == 1
    assert len(back) == len(eph) - 1 and eph.times_utc[k] not in back.times_utc


@pytest.mark.parametrize("dv_mps", [0.01, 1.0, 10.0])
def test_a_burn_is_never_an_outlier(dv_mps: float) -> None:
    """A burn changes the velocity, not the position: no epoch around it is removed."""
    eph = _truth()
    burned = inject_impulse(eph, eph.times_utc[150] + np.timedelta64(17, "s"), (0.3 * dv_mps, dv_mps, 0.2 * dv_mps))
    assert not single_epoch_outliers(burned.seconds, burned.position_m).any()


def test_a_step_of_every_later_record_is_not_an_outlier() -> None:
    eph = _truth()
    stepped = eph.position_m.copy()
    stepped[150:] += 50.0
    assert not single_epoch_outliers(eph.seconds, stepped).any()


def test_noise_alone_removes_nothing_on_many_arcs() -> None:
    """Navigation-like noise (σ 10 m): no epoch of 20 arcs of 6 h is called an outlier."""
    removed = 0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        eph = _truth(sigma_pos_m=0.0)
        removed += int(
            single_epoch_outliers(eph.seconds, eph.position_m + rng.normal(0, 10.0, eph.position_m.shape)).sum()
        )
    assert removed == 0


def test_noise_that_grows_tenfold_along_the_arc_removes_nothing() -> None:
    """5 cm noise, then 50 cm: the level is each part's own (a level from the whole arc called 2 % of the
    noisier half's epochs outliers)."""
    eph = _truth(sigma_pos_m=0.0)
    rng = np.random.default_rng(8)
    sigma = np.where(eph.seconds < 3 * 3600.0, 0.05, 0.5)[:, None]
    noisy = eph.position_m + rng.normal(0.0, 1.0, eph.position_m.shape) * sigma
    assert not single_epoch_outliers(eph.seconds, noisy).any()
    bad = noisy.copy()
    bad[300] += 20.0  # 40 σ of the noisier half
    assert np.flatnonzero(single_epoch_outliers(eph.seconds, bad)).tolist() == [300]


def test_an_eccentric_orbit_removes_nothing() -> None:
    eph = _truth(altitude_km=20000.0, eccentricity=0.6)  # perigee 4170 km altitude, 60 s steps
    assert len(check_orbit_envelope(eph)) == len(eph)


# ------------------------------------------------------------------------------------------ gaps, short arcs


def test_a_gap_longer_than_half_a_revolution_splits_the_arcs() -> None:
    eph = _truth()
    limit = bridge_limit_s(eph)
    period = 2 * np.pi * np.sqrt(np.median(np.linalg.norm(eph.position_m, axis=1)) ** 3 / 3.986004418e14)
    assert limit == pytest.approx(period / 2, rel=1e-12)
    t = eph.times_utc.copy()
    t[200:] += np.timedelta64(round(limit * 1.2), "s")  # a gap of 1.2 limits after epoch 199
    t[300:] += np.timedelta64(round(limit * 0.5), "s")  # and one of half a limit (bridged) after 299
    assert data_arcs(t, limit) == [(0, 200), (200, len(t))]
    assert data_arcs(eph.times_utc, limit) == [(0, len(t))]


def test_an_sp3_whose_second_half_is_three_hours_late_gives_no_event(tmp_path: Path) -> None:
    """The time tags of the second half moved 3 h later: the filters would have propagated across the
    3 h and found a 7 km/s "burn". The gap ends one arc; nothing is tested across it, and the run says so."""
    eph = _itrf(_truth())
    t = eph.times_utc.copy()
    t[len(t) // 2 :] += np.timedelta64(3, "h")
    path = tmp_path / "late.sp3"
    write_sp3(replace(eph, times_utc=t), path)
    run = detect_orbit(path)
    assert len(run.events) == 0
    assert any(w.startswith("gap of 3.02 h") and "nothing tested in the gap" in w for w in run.result.warnings)


def test_an_arc_too_short_to_test_is_a_warning_and_a_recorded_run(tmp_path: Path) -> None:
    """A 4.95 h arc (the filters settle 3.3 h at each end): exit 0, a warning, an empty events file and a
    run in the catalog, so that a batch over many files does not stop."""
    eph = _itrf(_truth())
    short = eph.select(eph.seconds <= 4.95 * 3600)
    path = tmp_path / "stella.sp3"
    write_sp3(short, path)
    events, catalog = tmp_path / "events.csv", tmp_path / "catalog.sqlite"
    result = CliRunner().invoke(
        cli, ["detect", "orbit", str(path), "--out", str(events), "--catalog", str(catalog)], catch_exceptions=False
    )
    assert result.exit_code == 0, result.output
    assert "warning: nothing tested: the arc spans 4.95 h" in result.output
    assert len(pd.read_csv(events)) == 0
    runs = Catalog(str(catalog)).runs()
    assert list(runs["command"]) == ["detect orbit"]


def _write_cpf(eph: Ephemeris, path: Path) -> None:
    """An ILRS CPF v2 of an Earth-fixed ephemeris (positions only, ``10`` records), LAGEOS-1 ids."""
    lines = [
        "H1 CPF 2 HTS 2018 6 13 12 164 1 lageos1 NONE",
        "H2 7603901 1155 8820 2018 6 13 0 0 0 2018 6 15 0 0 0 240 1 1 0 0 0 1",
        "H9",
    ]
    mjd0 = 58282  # 2018-06-14
    for t, r in zip(eph.times_utc, eph.position_m, strict=True):
        sec = float((t - np.datetime64("2018-06-14", "ns")) / np.timedelta64(1, "s"))
        day, sod = divmod(sec, 86400.0)
        lines.append(f"10 0 {mjd0 + int(day)} {sod:12.5f} 0 {r[0]:14.3f} {r[1]:14.3f} {r[2]:14.3f}")
    lines.append("99")
    path.write_text("\n".join(lines) + "\n")


def test_a_50_km_jump_in_one_cpf_record_is_an_outlier_not_a_burn(tmp_path: Path) -> None:
    """A LAGEOS-like CPF prediction (5900 km, 240 s): one record 50 km off is removed and counted; the
    detector never sees it."""
    cfg = OrbitSimulationConfig(
        altitude_m=5900e3,
        inclination_deg=109.8,
        duration_s=86400.0,
        rate_hz=1 / 240,
        sigma_pos_m=0.0,
        sigma_vel_mps=0.0,
        epoch_utc="2018-06-14T00:00:00",
        forces=ForceModel(zonal_degree=2),
    )
    eph = _itrf(simulate_orbit(cfg).ephemeris("lageos1"))
    bad = eph.position_m.copy()
    bad[200] += np.array([30e3, -40e3, 0.0])
    path = tmp_path / "lageos1.hts"
    _write_cpf(replace(eph, position_m=bad), path)
    back = read_ephemeris(path)
    assert back.repairs.counts[OUTLIER_REPAIR] == 1
    assert len(back) == len(eph) - 1 and eph.times_utc[200] not in back.times_utc
    np.testing.assert_allclose(back.position_m, np.delete(eph.position_m, 200, axis=0), atol=1e-3)


def test_every_satellite_of_a_product_too_short_to_test_is_a_run_that_tested_nothing() -> None:
    eph = _itrf(_truth())
    short = eph.select(eph.seconds <= 4.0 * 3600)
    runs = detect_orbit_product({"L27": short, "L28": replace(short, satellite="L28")})
    assert sorted(runs) == ["L27", "L28"]
    for run in runs.values():
        assert run.summary["tested"] is False and len(run.events) == 0
        assert run.result.warnings[0].startswith("nothing tested: the arc spans 4 h")
