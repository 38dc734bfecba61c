"""Every event-writing code path writes only registered detector names.

Each case runs one pipeline end to end on a small input holding at least one event, collects the
``detector`` of every event it produced (and, where the command line writes the events, of the events
file and of the catalog both) and checks each name against
:func:`abrupt.detect.base.detector_names`. Every case must produce events, so the check cannot pass
on an empty frame.

Left out on purpose: the simulators' truth tables (``abrupt simulate tracking --truth-out``,
``SimulatedTracking.truth_events``) use the reserved name ``"truth"``: they say where the events
really are, they are not detections. ``abrupt inject attitude`` writes telemetry and a recovery table,
``abrupt inject orbit`` an ephemeris and ``abrupt inject tle`` a table of injected burns: none of
them writes events. The density from TLEs writes windows, not events; its maneuver cut is checked
here by the detector names of the events it cut at.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pandas as pd
import pytest
from click.testing import CliRunner

import abrupt.density.tle_drag as tle_drag
import abrupt.pipelines.mass as mass_pipeline
from abrupt.catalog import Catalog
from abrupt.cli.main import cli
from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.detect.attitude.momentum import AttitudeDetectionConfig, attitude_detector_names
from abrupt.detect.base import DetectionResult, Detector, detector_names
from abrupt.detect.tle.config import DEFAULT_TLE_BUDGET
from abrupt.detect.tle.detectors import detector_for
from abrupt.errors import RepairLog
from abrupt.events import read_events
from abrupt.model.spacecraft import bundled_spacecraft_path
from abrupt.pipelines.attitude import detect_attitude
from abrupt.pipelines.fleet import FleetMember, detect_attitude_fleet, detect_tle_batch
from abrupt.pipelines.flight import ingest_archives
from abrupt.pipelines.tle import detect_tle_file
from abrupt.readers.ephemeris import write_ephemeris
from abrupt.readers.tle import ElementHistory, read_tle
from abrupt.simulate.slr import SlrScenario, simulate_slr
from abrupt.thresholds import FalseAlarmBudget
from detector_examples import attitude_example, inertia_track_example, orbit_example
from flight_synth import make_archive
from test_laser_ranging_cli import write_apriori, write_crd, write_sinex
from test_tle_synthetic import synthetic_tle_text


def _registered(events: pd.DataFrame, where: str) -> set[str]:
    """The detector names of ``events`` (at least one event), each checked against the registry."""
    assert len(events) > 0, f"{where}: no events, so the check would pass vacuously"
    names = set(events["detector"].astype(str))
    unknown = names - set(detector_names())
    assert not unknown, f"{where}: events under unregistered detector name(s) {sorted(unknown)}"
    return names


def _invoke(args: list[str]) -> None:
    result = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output


def _cli_names(args: list[str], tmp: Path, *, out_flag: str = "--out") -> set[str]:
    """Run a detect command writing an events file and a catalog; the names of both, which must agree."""
    tmp.mkdir(parents=True, exist_ok=True)
    out, catalog = tmp / "events.csv", tmp / "catalog.sqlite"
    _invoke([*args, out_flag, str(out), "--catalog", str(catalog)])
    in_file = _registered(read_events(str(out)), f"{' '.join(args[:2])}: events file")
    in_catalog = _registered(Catalog(str(catalog)).events(), f"{' '.join(args[:2])}: catalog")
    assert in_file == in_catalog
    return in_file


def _tle_file(tmp: Path) -> Path:
    text, _ = synthetic_tle_text(days=200, burns=((100.3, 0.02),), seed=2)
    path = tmp / "leo.tle"
    path.write_text(text)
    return path


# ---------------------------------------------------------------------------------------------- cases


def case_attitude(tmp: Path) -> set[str]:
    """pipelines.attitude.detect_attitude with every attitude detector (change detectors and matched filters)."""
    series = attitude_example()
    config = AttitudeDetectionConfig(
        detectors=attitude_detector_names(), null_samples=10_000, threshold_method="empirical"
    )
    run = detect_attitude(series.telemetry, series.spacecraft, config, budget=FalseAlarmBudget(2.0, "week"))
    names = _registered(run.events, "detect_attitude")
    assert names == set(attitude_detector_names())  # every detector found the strike
    return names


def _simulated_telemetry(tmp: Path) -> Path:
    tel = tmp / "tel.csv"
    _invoke(["simulate", "attitude", "--duration", "600", "--strike", "300:0.2,-0.15,0.17", "--seed", "11",
             "--out", str(tel)])  # fmt: skip
    return tel


def case_attitude_cli(tmp: Path) -> set[str]:
    """``abrupt simulate attitude`` then ``abrupt detect attitude`` with a change detector and a matched filter."""
    sc = bundled_spacecraft_path("thesis")
    args = ["detect", "attitude", str(_simulated_telemetry(tmp)), "--spacecraft", str(sc)]
    args += ["--detector", "glr", "--detector", "mf_joint"]
    return _cli_names([*args, "--threshold-fit", "empirical", "--null-samples", "100000"], tmp)


def case_flight(tmp: Path) -> set[str]:
    """The flight pipeline (``abrupt detect attitude --store``) on a small synthetic archive."""
    a = make_archive(tmp, hours=4.0, strikes=[(7200.0, [0.06, -0.05, 0.04])])
    ingest_archives([a.archive], a.decoder, tmp / "store")
    args = ["detect", "attitude", "--store", str(tmp / "store"), "--spacecraft", str(a.spacecraft)]
    return _cli_names(args, tmp)


def case_orbit(tmp: Path) -> set[str]:
    """``abrupt detect orbit`` (the command builds its run itself) on a simulated ephemeris with an impulse,
    with the default statistic of each tuning and two more by name."""
    path = tmp / "orbit.csv"
    write_ephemeris(orbit_example(), path)
    args = ["detect", "orbit", str(path), "--tuning", "thesis", "--sigma-pos-m", "1", "--sigma-vel-mps", "1e-3"]
    args += ["--tau-s", "600", "--q", "1e-12", "--dynamics", "two-body", "--false-alarms", "2/week"]
    names = _cli_names(args, tmp / "default")
    names |= _cli_names([*args, "--statistic", "glr"], tmp / "glr")
    names |= _cli_names([*args, "--detector", "orbit.dv_fb"], tmp / "dv_fb")
    assert names == {"orbit.mcr_w", "orbit.glr", "orbit.dv_fb"}
    return names


def case_tle(tmp: Path) -> set[str]:
    """``abrupt detect tle`` on a synthetic LEO history with a 2 cm/s burn, and the pipeline on it directly."""
    path = _tle_file(tmp)
    direct = _registered(detect_tle_file(path, DEFAULT_TLE_BUDGET).events, "detect_tle_file")
    assert direct == _cli_names(["detect", "tle", str(path)], tmp) == {"tle.mean_elements"}
    return direct


def case_tle_geo(tmp: Path) -> set[str]:
    """The TLE pipeline with the GEO station-keeping detector (forced) on the same history."""
    path = _tle_file(tmp)
    events = detect_tle_file(path, DEFAULT_TLE_BUDGET, detector="tle.geo_station_keeping").events
    names = _registered(events, "detect_tle_file (GEO)")
    assert names == {"tle.geo_station_keeping"}
    return names


def case_tle_batch(tmp: Path) -> set[str]:
    """pipelines.fleet.detect_tle_batch in-process, and ``abrupt detect tle-batch``."""
    path = _tle_file(tmp)
    direct = _registered(detect_tle_batch([path], DEFAULT_TLE_BUDGET), "detect_tle_batch")
    assert direct == _cli_names(["detect", "tle-batch", str(path)], tmp)
    return direct


def case_attitude_fleet(tmp: Path) -> set[str]:
    """pipelines.fleet.detect_attitude_fleet in-process (events and catalog), and ``abrupt detect fleet``."""
    tel = _simulated_telemetry(tmp)
    sc = bundled_spacecraft_path("thesis")
    config = AttitudeDetectionConfig(detectors=("glr", "mf_rate"), null_samples=100_000, threshold_method="empirical")
    result = detect_attitude_fleet([FleetMember("SC-F", str(tel), str(sc))], config, catalog=tmp / "fleet.sqlite")
    names = _registered(result.events, "detect_attitude_fleet")
    assert names == _registered(Catalog(str(tmp / "fleet.sqlite")).events(), "detect_attitude_fleet: catalog")
    manifest = tmp / "fleet.csv"
    manifest.write_text(f"spacecraft,telemetry,spacecraft_file\nSC-G,{tel},{sc}\n")
    args = ["detect", "fleet", str(manifest), "--detector", "glr", "--null-samples", "100000"]
    names |= _cli_names(args, tmp / "cli")
    return names


def case_tracking(tmp: Path) -> set[str]:
    """``abrupt simulate tracking`` (its truth table is not a detection) then ``abrupt detect tracking``."""
    tdm = tmp / "track.tdm"
    truth = tmp / "truth.csv"
    _invoke(["simulate", "tracking", "--out", str(tdm), "--truth-out", str(truth), "--cadence", "20", "--seed", "4"])
    assert set(read_events(str(truth))["detector"]) == {"truth"}
    args = ["detect", "tracking", str(tdm), "--setup", str(tdm.with_suffix(".in")), "--max-maneuvers", "1"]
    args += ["--kaderali-threshold", "chi2"]
    names = _cli_names(args, tmp)
    assert names == {"tracking.glrt", "tracking.kaderali_k"}
    return names


def case_laser(tmp: Path) -> set[str]:
    """``abrupt detect laser`` on CRD/SINEX/OEM files of a simulated day with a 1 cm/s impulse (several
    minutes: the command fits the real-data force model arc by arc)."""
    scenario = SlrScenario(duration_days=1.0, pass_probability=1.0, maneuver_t_s=50000.0,
                           maneuver_dv_rsw_mps=(0.003, 0.008, -0.005))  # fmt: skip
    sim = simulate_slr(scenario, seed=11)
    crd, snx, oem = tmp / "l.npt", tmp / "s.snx", tmp / "a.oem"
    write_crd(sim, crd)
    write_sinex(sim, snx)
    write_apriori(sim, oem)
    return _cli_names(["detect", "laser", str(crd), "--sinex", str(snx), "--apriori", str(oem)], tmp)


def case_density_tle(tmp: Path, monkeypatch: pytest.MonkeyPatch) -> set[str]:
    """The maneuver cut of the density from TLEs: the detector it runs and the events it cuts at."""
    used: list[pd.DataFrame] = []

    def spy(history: ElementHistory) -> Detector[Any]:
        det = detector_for(history)
        detect = det.detect

        def recording(series: Any, budget: FalseAlarmBudget) -> DetectionResult:
            result = detect(series, budget)
            used.append(result.events)
            return result

        det.detect = recording  # type: ignore[method-assign]
        return det

    monkeypatch.setattr(tle_drag, "detector_for", spy)
    history = read_tle(_tle_file(tmp))
    res = rho_b_from_history(history, TleDragConfig(), maneuvers="detect")
    assert used, "the density's maneuver cut ran no detector"
    events = pd.concat(used, ignore_index=True)
    assert len(res.maneuver_epochs_utc) == len(events) > 0
    return _registered(events, "density maneuver cut")


def case_mass(tmp: Path, monkeypatch: pytest.MonkeyPatch) -> set[str]:
    """``abrupt detect mass-change``: its detector and event writing, on the inertia-track example (the
    telemetry reading and the inertia tracking are replaced by the example track; see the slow case for
    the whole chain)."""
    monkeypatch.setattr(mass_pipeline, "_load", lambda *_: (SimpleNamespace(nadir_N=None), RepairLog()))
    monkeypatch.setattr(mass_pipeline, "track_inertia", lambda *_, **__: inertia_track_example())
    sc = tmp / "sc.toml"
    sc.write_text(MASS_SPACECRAFT)
    tel = tmp / "tel.csv"
    tel.write_text("time\n")
    return _cli_names(["detect", "mass-change", str(tel), "--spacecraft", str(sc), "--false-alarms", "1/year"], tmp)


MASS_SPACECRAFT = (
    'name = "SC-X"\nmass_kg = 1000.0\ninertia_kgm2 = [[900.0, 5.0, -3.0], [5.0, 700.0, 2.0], [-3.0, 2.0, 1000.0]]\n'
    + "".join(
        f'[[wheels]]\nname = "rw{i}"\naxis = {a}\nspin_inertia_kgm2 = 0.12\nmax_torque_Nm = 0.2\n'
        for i, a in enumerate([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]])
    )
)


def case_mass_docking(tmp: Path) -> set[str]:
    """``abrupt simulate docking`` (100 kg) then ``abrupt detect mass-change`` on its telemetry: the whole chain."""
    sc = tmp / "sc.toml"
    sc.write_text(MASS_SPACECRAFT)
    sim = tmp / "sim"
    _invoke(["simulate", "docking", "--spacecraft", str(sc), "--out", str(sim), "--days", "1.0",
             "--docking-day", "0.5", "--mass", "100", "--seed", "5"])  # fmt: skip
    args = ["detect", "mass-change", "--store", str(sim), "--spacecraft", str(sc), "--orbit-period", "5926.4"]
    return _cli_names([*args, "--window", "10800", "--false-alarms", "1/week"], tmp)


def case_demo(tmp: Path) -> set[str]:
    """``abrupt demo``: simulated telemetry with strikes, detected and written to events and catalog."""
    _invoke(["demo", "--out", str(tmp), "--duration", "1800"])
    in_file = _registered(read_events(str(tmp / "events.csv")), "demo: events file")
    assert in_file == _registered(Catalog(str(tmp / "catalog.sqlite")).events(), "demo: catalog")
    return in_file


#: The cases by pipeline; the slow ones each have a fast case of the same family above them.
CASES: dict[str, Callable[..., set[str]]] = {
    "attitude": case_attitude,
    "attitude_cli": case_attitude_cli,
    "attitude_fleet": case_attitude_fleet,
    "flight": case_flight,
    "orbit": case_orbit,
    "tle": case_tle,
    "tle_geo": case_tle_geo,
    "tle_batch": case_tle_batch,
    "density_tle": case_density_tle,
    "tracking": case_tracking,
    "laser": case_laser,
    "mass": case_mass,
    "mass_docking": case_mass_docking,
    "demo": case_demo,
}
SLOW = {"laser", "mass_docking", "demo"}
NEEDS_MONKEYPATCH = {"density_tle", "mass"}


@pytest.mark.parametrize("case", [pytest.param(c, id=c, marks=[pytest.mark.slow] if c in SLOW else []) for c in CASES])
def test_every_event_carries_a_registered_detector(case: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fn = CASES[case]
    names = fn(tmp_path, monkeypatch) if case in NEEDS_MONKEYPATCH else fn(tmp_path)
    assert names and names <= set(detector_names())


def test_the_truth_name_is_reserved() -> None:
    """The simulators' truth tables are told apart by a name no detector may take."""
    assert "truth" not in detector_names()
