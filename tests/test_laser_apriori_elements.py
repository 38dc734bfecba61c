"""``abrupt detect laser --apriori X.tle``: the a-priori orbit from element sets (SGP4), fitted to the
ranges over a short arc before detection.

Truths: astropy's TEME→GCRS transformation (another implementation of the frames) for the SGP4 state;
the simulated orbit for the short-arc fit. The element set of the test is built from the true state
with astropy's GCRS→TEME and two-body (osculating) elements taken as SGP4 mean elements, so SGP4 starts
kilometres off the truth, as an element set does.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import astropy.units as u
import numpy as np
import pandas as pd
import pytest
from astropy.coordinates import GCRS, TEME, CartesianDifferential, CartesianRepresentation
from astropy.time import Time
from click.testing import CliRunner
from sgp4.api import WGS72, Satrec
from sgp4.exporter import export_omm, export_tle

from abrupt.cli.main import cli, main
from abrupt.model.orbit import propagate
from abrupt.model.teme import sgp4_state_gcrf
from abrupt.model.timescales import offline_astropy
from abrupt.pipelines.laser_apriori import ElementApriori, is_element_file, short_arc_fit
from abrupt.pipelines.laser_ranging import (
    LASER_FIT_CONFIG,
    LASER_FORCE,
    laser_stations,
    ranges_from_crd,
    sites_from_sinex,
)
from abrupt.readers.crd import read_crd
from abrupt.readers.sinex import read_sinex
from abrupt.simulate.slr import SlrScenario, SlrSimulation, simulate_slr
from test_laser_ranging_cli import write_crd, write_sinex

OMM_METADATA = ("OBJECT_NAME", "OBJECT_ID", "CENTER_NAME", "REF_FRAME", "TIME_SYSTEM", "MEAN_ELEMENT_THEORY")
MU_WGS72_KM3_S2 = 398600.8  # [km^3/s^2] the gravity constant of SGP4's WGS-72


def _osculating_elements(r_km: np.ndarray, v_kms: np.ndarray) -> tuple[float, ...]:
    """(a [km], e, i, RAAN, argument of perigee, mean anomaly [rad]) of a two-body state (Vallado 2013,
    Algorithm 9)."""
    h = np.cross(r_km, v_kms)
    node = np.cross([0.0, 0.0, 1.0], h)
    r, v = np.linalg.norm(r_km), np.linalg.norm(v_kms)
    e_vec = ((v**2 - MU_WGS72_KM3_S2 / r) * r_km - np.dot(r_km, v_kms) * v_kms) / MU_WGS72_KM3_S2
    e = float(np.linalg.norm(e_vec))
    a = 1.0 / (2.0 / r - v**2 / MU_WGS72_KM3_S2)
    inc = float(np.arccos(h[2] / np.linalg.norm(h)))
    raan = float(np.arctan2(node[1], node[0]) % (2 * np.pi))
    argp = float(np.arccos(np.dot(node, e_vec) / np.linalg.norm(node) / e))
    argp = argp if e_vec[2] >= 0 else 2 * np.pi - argp
    nu = float(np.arccos(np.clip(np.dot(e_vec, r_km) / e / r, -1.0, 1.0)))
    nu = nu if np.dot(r_km, v_kms) >= 0 else 2 * np.pi - nu
    ecc_anomaly = 2.0 * np.arctan(np.sqrt((1 - e) / (1 + e)) * np.tan(nu / 2))
    return a, e, inc, raan, argp, float((ecc_anomaly - e * np.sin(ecc_anomaly)) % (2 * np.pi))


def tle_from_state(x_gcrf: np.ndarray, epoch_utc: np.datetime64, norad: int = 8820) -> tuple[str, str]:
    """A TLE whose mean elements are the osculating elements of a GCRF state (astropy's GCRS→TEME)."""
    offline_astropy()
    t = Time(np.datetime64(epoch_utc, "ns"), format="datetime64", scale="utc")
    rep = CartesianRepresentation(x_gcrf[:3] * u.m, differentials=CartesianDifferential(x_gcrf[3:] * u.m / u.s))
    teme = GCRS(rep, obstime=t).transform_to(TEME(obstime=t))
    a, e, inc, raan, argp, mean_anomaly = _osculating_elements(
        teme.cartesian.xyz.to_value(u.km), teme.velocity.d_xyz.to_value(u.km / u.s)
    )
    sat = Satrec()
    days = (np.datetime64(epoch_utc, "ns") - np.datetime64("1949-12-31T00:00", "ns")) / np.timedelta64(1, "D")
    n_rad_min = np.sqrt(MU_WGS72_KM3_S2 / a**3) * 60.0
    sat.sgp4init(WGS72, "i", norad, float(days), 0.0, 0.0, 0.0, e, argp, inc, mean_anomaly, n_rad_min, raan)
    line1, line2 = export_tle(sat)
    return line1, line2


@pytest.mark.parametrize("epoch", ["2010-05-05T03:00:00", "2024-03-01T00:00:00", "2022-12-31T23:59:30"])
def test_sgp4_state_in_gcrf_agrees_with_astropys_teme_transformation(epoch: str) -> None:
    offline_astropy()
    line1 = "1 08820U 76039A   24061.00000000  .00000000  00000-0  00000-0 0  9998"
    line2 = "2 08820 109.8400  40.0000 0045000 250.0000  10.0000  6.38664000    09"
    sat = Satrec.twoline2rv(line1, line2)
    t64 = np.datetime64(epoch, "ns")
    mine = sgp4_state_gcrf(sat, t64)
    t = Time(t64, format="datetime64", scale="utc")
    _, r_km, v_kms = sat.sgp4(t.jd1, t.jd2)
    rep = CartesianRepresentation(np.asarray(r_km) * u.km, differentials=CartesianDifferential(v_kms * u.km / u.s))
    gcrs = TEME(rep, obstime=t).transform_to(GCRS(obstime=t))
    # IAU 1976/1980 (here) against IAU 2006/2000A (astropy): milliarcseconds, a few metres at 12,000 km
    assert np.linalg.norm(mine[:3] - gcrs.cartesian.xyz.to_value(u.m)) < 5.0
    assert np.linalg.norm(mine[3:] - gcrs.velocity.d_xyz.to_value(u.m / u.s)) < 1e-3


@pytest.mark.parametrize("fmt", ["kvn", "json", "xml"])
def test_an_omm_gives_the_apriori_of_its_tle(tmp_path: Path, fmt: str) -> None:
    line1 = "1 08820U 76039A   24061.00000000  .00000000  00000-0  00000-0 0  9998"
    line2 = "2 08820 109.8400  40.0000 0045000 250.0000  10.0000  6.38664000    09"
    line1, line2 = export_tle(Satrec.twoline2rv(line1, line2))  # with their checksums
    record = export_omm(Satrec.twoline2rv(line1, line2), "LAGEOS-1")
    texts = {
        "kvn": "CCSDS_OMM_VERS = 2.0\n" + "".join(f"{k} = {v}\n" for k, v in record.items()),
        "json": json.dumps([record]),
        "xml": '<?xml version="1.0" encoding="UTF-8"?><omm id="CCSDS_OMM_VERS" version="2.0"><body><segment>'
        + "<metadata>"
        + "".join(f"<{k}>{record[k]}</{k}>" for k in OMM_METADATA if k in record)
        + "</metadata><data><meanElements>"
        + "".join(f"<{k}>{v}</{k}>" for k, v in record.items() if k not in OMM_METADATA)
        + "</meanElements></data></segment></body></omm>",
    }
    omm, tle = tmp_path / f"lageos.{fmt}", tmp_path / "lageos.tle"
    omm.write_text(texts[fmt])
    tle.write_text(f"{line1}\n{line2}\n")
    assert is_element_file(omm) and is_element_file(tle)
    t = np.datetime64("2024-03-01T06:00:00", "ns")
    from_omm, from_tle = ElementApriori.read(omm).state_gcrf(t), ElementApriori.read(tle).state_gcrf(t)
    assert from_omm is not None and from_tle is not None
    assert np.linalg.norm(from_omm[:3] - from_tle[:3]) < 1.0  # [m]: the same elements, to their printed digits


@pytest.fixture(scope="module")
def campaign(tmp_path_factory: pytest.TempPathFactory) -> tuple[SlrSimulation, dict[str, Path]]:
    """One simulated LAGEOS day (20 % more radiation pressure than the a-priori C_R) as CRD and SINEX,
    with a TLE of the true orbit at the campaign start."""
    truth = replace(LASER_FORCE, srp_coefficient=1.2 * LASER_FORCE.srp_coefficient)
    sim = simulate_slr(SlrScenario(duration_days=1.0, noise_m=0.003, force=truth), seed=21)
    d = tmp_path_factory.mktemp("laser_tle")
    paths = {"crd": d / "lageos1.npt", "snx": d / "sites.snx", "tle": d / "lageos1.tle", "old": d / "old.tle"}
    write_crd(sim, paths["crd"])
    write_sinex(sim, paths["snx"])
    paths["tle"].write_text("\n".join(tle_from_state(sim.x0, sim.epoch_utc)) + "\n")
    stale = sim.epoch_utc - np.timedelta64(60, "D")
    paths["old"].write_text("\n".join(tle_from_state(sim.x0, stale)) + "\n")
    return sim, paths


def test_short_arc_fit_brings_the_sgp4_state_to_the_simulated_orbit(
    campaign: tuple[SlrSimulation, dict[str, Path]],
) -> None:
    sim, paths = campaign
    meas = ranges_from_crd(read_crd(str(paths["crd"])))
    meas["station"] = meas["station_id"].astype(str)
    epoch = np.datetime64(pd.Timestamp(meas["time_utc"].min()).floor("s"), "ns")
    sites = sites_from_sinex(read_sinex(str(paths["snx"])), sorted(meas["station"].unique()), epoch)
    stations = laser_stations(sites, meas)
    x_sgp4 = sgp4_state_gcrf(Satrec.twoline2rv(*paths["tle"].read_text().split("\n")[:2]), epoch)
    dt_s = float((epoch - sim.epoch_utc) / np.timedelta64(1, "s"))
    x_true = propagate(sim.x0, np.array([dt_s]), force=sim.force)[0]
    assert np.linalg.norm(x_sgp4[:3] - x_true[:3]) > 1_000.0  # the element set is kilometres off
    cfg = replace(LASER_FIT_CONFIG, force=sim.scenario.force)
    x_fit, info = short_arc_fit(meas, sites, stations, x_sgp4, epoch, cfg)
    # measured 9 mm and 6 µm/s from 50 km and 20 m/s; range biases (5 mm spread) are not fitted here
    assert np.linalg.norm(x_fit[:3] - x_true[:3]) < 0.2  # [m]
    assert np.linalg.norm(x_fit[3:] - x_true[3:]) < 1e-4  # [m/s]
    assert float(info["short_arc_rms_m"]) < 0.1  # type: ignore[arg-type]


def test_detect_laser_from_a_tle_fits_the_orbit_then_stays_quiet(
    campaign: tuple[SlrSimulation, dict[str, Path]], tmp_path: Path
) -> None:
    _, paths = campaign
    out, fit_out = tmp_path / "events.csv", tmp_path / "fit.json"
    args = ["detect", "laser", str(paths["crd"]), "--sinex", str(paths["snx"]), "--apriori", str(paths["tle"])]
    args += ["--out", str(out), "--catalog", str(tmp_path / "c.sqlite"), "--fit-out", str(fit_out)]
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    assert len(pd.read_csv(out)) == 0
    fit = pd.read_json(fit_out, typ="series")
    (apriori,) = fit["apriori_from_elements"]
    assert apriori["sgp4_position_offset_m"] > 1_000.0 and apriori["short_arc_rms_m"] < 0.1
    assert max(fit["residual_rms_mm"].values()) < 3 * 3.0  # mm, against 3 mm normal points
    assert fit["scale_factors"]["srp_scale"] == pytest.approx(1.2, abs=0.1)


def test_detect_laser_refuses_element_sets_months_from_the_ranges(
    campaign: tuple[SlrSimulation, dict[str, Path]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, paths = campaign
    args = ["detect", "laser", str(paths["crd"]), "--sinex", str(paths["snx"]), "--apriori", str(paths["old"])]
    args += ["--out", str(tmp_path / "e.csv"), "--catalog", str(tmp_path / "c.sqlite")]
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {paths['old']}: ")
    assert "nearest the first range epoch 2024-03-01T02:10:20Z" in err[0] and "is 60 days from it" in err[0]


@pytest.mark.slow
def test_detect_laser_from_a_tle_finds_a_1_cm_per_s_maneuver(tmp_path: Path) -> None:
    """Two simulated days with a (3, 8, −5) mm/s burn at 80,000 s; the a-priori from a TLE of the true
    orbit: the burn is found at its time with its ΔV within 20 %."""
    dv_true = np.array([0.003, 0.008, -0.005])
    scenario = SlrScenario(duration_days=2.0, maneuver_t_s=80000.0, maneuver_dv_rsw_mps=tuple(dv_true))  # type: ignore[arg-type]
    scenario = replace(scenario, force=LASER_FORCE)
    sim = simulate_slr(scenario, seed=11)
    crd, snx, tle = tmp_path / "l.npt", tmp_path / "s.snx", tmp_path / "l.tle"
    write_crd(sim, crd)
    write_sinex(sim, snx)
    tle.write_text("\n".join(tle_from_state(sim.x0, sim.epoch_utc)) + "\n")
    out = tmp_path / "events.csv"
    args = ["detect", "laser", str(crd), "--sinex", str(snx), "--apriori", str(tle), "--out", str(out)]
    args += ["--catalog", str(tmp_path / "c.sqlite")]
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    events = pd.read_csv(out)
    assert len(events) == 1
    t = (pd.Timestamp(events["time_utc"].iloc[0].rstrip("Z")) - pd.Timestamp(sim.epoch_utc)).total_seconds()
    assert abs(t - 80000.5) < 3 * float(events["time_sigma_s"].iloc[0]) + 0.5
    dv = events[["dv_r_mps", "dv_t_mps", "dv_n_mps"]].to_numpy(float)[0]
    assert np.linalg.norm(dv - dv_true) < 0.2 * np.linalg.norm(dv_true)
