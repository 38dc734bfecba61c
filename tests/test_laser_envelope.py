"""Laser ranging inside its physical envelope: ranges against the a-priori orbit, the file's wavelength in
the troposphere, fitted biases and force scales bounded.

Simulated LAGEOS-like normal points (every term of the range model in the truth) written as CRD, the
stations as SINEX and the a-priori orbit as OEM (the writers of ``test_laser_ranging_cli``): the truth is
the simulation, and the dispersion of the troposphere is checked against the refractivity formula of
Ciddor as the IERS Conventions (2010, Eq. 9.14) give it, computed here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from abrupt.errors import InputError
from abrupt.events import Event, events_frame
from abrupt.model.orbit import propagate
from abrupt.model.range_reduction import RangeModel, reduce_ranges
from abrupt.pipelines.laser_plausibility import fit_bound_violations, passive_detections
from abrupt.pipelines.laser_ranging import LASER_FORCE, run_laser_ranging_files
from abrupt.readers.crd import read_crd
from abrupt.simulate.slr import SlrScenario, SlrSimulation, simulate_slr, trajectory_interpolator
from abrupt.thresholds import FalseAlarmBudget
from test_laser_ranging_cli import write_apriori, write_crd, write_sinex


@pytest.fixture(scope="module")
def sim() -> SlrSimulation:
    return simulate_slr(SlrScenario(duration_days=1.0, noise_m=0.003, force=LASER_FORCE), seed=21)


@pytest.fixture(scope="module")
def files(sim: SlrSimulation, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("laser_envelope")
    paths = {"crd": d / "lageos1.npt", "snx": d / "sites.snx", "oem": d / "apriori.oem"}
    write_crd(sim, paths["crd"])
    write_sinex(sim, paths["snx"])
    write_apriori(sim, paths["oem"])
    return paths


def _scaled_crd(source: Path, target: Path, factor: float, station: str | None = None) -> None:
    """The CRD file with the time of flight of every range record (of one station) times ``factor``."""
    out, current = [], None
    for line in source.read_text().splitlines():
        if line.startswith("H2"):
            current = line.split()[2]
        if line.startswith("11 ") and (station is None or current == station):
            tokens = line.split(" ")
            tokens[2] = f"{float(tokens[2]) * factor:.12f}"
            line = " ".join(tokens)
        out.append(line)
    target.write_text("\n".join(out) + "\n")


@pytest.mark.parametrize(("factor", "station"), [(0.001, None), (6.0, None), (6.0, "7839")])
def test_ranges_in_a_wrong_scale_are_refused_against_the_apriori_orbit(
    factor: float, station: str | None, files: dict[str, Path], tmp_path: Path
) -> None:
    bad = tmp_path / "scaled.npt"
    _scaled_crd(files["crd"], bad, factor, station)
    with pytest.raises(InputError) as info:
        run_laser_ranging_files([str(bad)], str(files["snx"]), str(files["oem"]), budget=FalseAlarmBudget(1, "week"))
    message = str(info.value)
    assert "\n" not in message and str(bad) in message
    assert "times those of the a-priori orbit" in message
    ratio = float(message.split("its ranges are ")[1].split(" times")[0])
    assert ratio == pytest.approx(factor, rel=1e-3)  # the a-priori is 50 m off: 1e-5 of a LAGEOS range
    if station is not None:
        assert f"station {station}:" in message


def _hydrostatic_dispersion(wavelength_um: float) -> float:
    """Ciddor's group refractivity of dry air (IERS Conventions 2010, Eq. 9.14, without the CO2 factor)."""
    k0, k1, k2, k3 = 238.0185, 19990.975, 57.362, 579.55174
    s2 = 1.0 / wavelength_um**2
    return k1 * (k0 + s2) / (k0 - s2) ** 2 + k3 * (k2 + s2) / (k2 - s2) ** 2


def test_the_crd_wavelength_sets_the_troposphere(sim: SlrSimulation, files: dict[str, Path]) -> None:
    """The same ranges reduced as green (532 nm) and as infrared (1064 nm) light: the tropospheric part
    of the correction scales by the dry-air dispersion ratio (0.955), the wet part being < 0.3 %."""
    grid = np.arange(0.0, 86400.0 + 60.0, 20.0)
    truth = trajectory_interpolator(grid, propagate(sim.x0, grid, force=sim.force))
    table = read_crd(files["crd"])
    assert np.all(table["wavelength_nm"] == 532.0)
    meas = sim.measurements

    def troposphere(wavelength_nm: float | None) -> np.ndarray:
        m = meas if wavelength_nm is None else meas.assign(wavelength_nm=wavelength_nm)
        kw = {"epoch_utc": sim.epoch_utc}
        full = reduce_ranges(m, sim.sites, truth, RangeModel(), **kw)  # type: ignore[arg-type]
        none = reduce_ranges(m, sim.sites, truth, RangeModel(troposphere="none"), **kw)  # type: ignore[arg-type]
        return full["range_correction_m"].to_numpy() - none["range_correction_m"].to_numpy()

    green, infrared, default = troposphere(532.0), troposphere(1064.0), troposphere(None)
    np.testing.assert_allclose(default, green, rtol=0, atol=1e-9)  # no column: the model's 532 nm
    expected = _hydrostatic_dispersion(1.064) / _hydrostatic_dispersion(0.532)
    assert float(np.median(infrared / green)) == pytest.approx(expected, rel=3e-3)
    assert float(np.min(green)) > 2.0  # the delay is metres: the ratio is measured, not noise


def test_a_wavelength_outside_ranging_lasers_names_the_line(files: dict[str, Path], tmp_path: Path) -> None:
    text = files["crd"].read_text().replace("C0 0 532.000 std1", "C0 0 0.532 std1", 1)  # µm written for nm
    bad = tmp_path / "micron.npt"
    bad.write_text(text)
    line = text[: text.index("C0 0 0.532")].count("\n") + 1
    with pytest.raises(InputError, match=rf"micron.npt:{line}:3: C0 wavelength 0.532 nm is not a ranging laser"):
        read_crd(bad)


def test_a_post_fit_residual_of_metres_is_named_as_one_the_fit_cannot_absorb() -> None:
    found = fit_bound_violations({"7090": 0.01}, {"srp_scale": 1.0}, {"7090": 0.004, "7839": 74e3})
    assert found == ["post-fit range RMS 7.4e+04 m at station 7839 (≤ 1 m)"]


@pytest.mark.parametrize(
    ("biases", "scales", "named"),
    [
        ({"7090": 0.02, "7839": -0.3}, {"srp_scale": 1.05}, []),
        ({"7090": 1.4}, {"srp_scale": 1.0}, ["range bias 1400 mm at station 7090"]),
        ({"7090": 0.0}, {"srp_scale": 7.8}, ["srp_scale 7.8"]),
        ({"7090": 0.0}, {"srp_scale": -0.5, "drag_scale": 10.0}, ["drag_scale 10", "srp_scale -0.5"]),
    ],
)
def test_fitted_biases_and_force_scales_outside_physics_are_named(
    biases: dict[str, float], scales: dict[str, float], named: list[str]
) -> None:
    found = fit_bound_violations(biases, scales)
    assert len(found) == len(named)
    for phrase, text in zip(named, found, strict=True):
        assert text.startswith(phrase)


def test_a_clean_day_passes_every_check_and_stays_within_bounds(files: dict[str, Path]) -> None:
    run = run_laser_ranging_files(
        [str(files["crd"])], str(files["snx"]), str(files["oem"]), budget=FalseAlarmBudget(1, "week")
    )
    # LAGEOS-1 (the CRD target) has no propulsion: the only warning states what its model explains
    assert len(run.summary["warnings"]) == 1 and run.summary["propulsion"] is False
    assert str(run.summary["warnings"][0]).startswith("lageos1 has no propulsion: its model explains")
    assert len(run.events) == 0
    last = run.result.arcs[-1].result.fit
    assert fit_bound_violations(last.range_bias_m, last.scale_factors, run.result.arcs[-1].result.residual_rms_m) == []


def test_laser_detections_of_a_passive_satellite_are_explained_or_named() -> None:
    """LAGEOS-1 over a 6 h gap between passes: radiation pressure (C_R = 2, +35 % albedo) accumulates
    0.19 mm/s; a 0.1 mm/s detection is explained, a 15 mm/s one is named as bad input, kind unknown."""
    t = "2024-03-01T00:00:00Z"
    events = events_frame(
        [
            Event("lageos1", "maneuver", "tracking.laser_glrt", t, 30.0, 20.0, 0.1, "r", "h", dv_t_mps=dv, dv_r_mps=0.0,
                  dv_n_mps=0.0)
            for dv in (1e-4, 0.015)
        ]
    )  # fmt: skip
    area_to_mass = 0.2827 / 406.965
    expected = 4.56e-6 * 2.0 * 1.35 * area_to_mass * 6 * 3600.0
    out, notes = passive_detections(events, "lageos1", area_to_mass, 6 * 3600.0)
    assert f"up to {1e3 * expected:.3g} mm/s" in notes[0]
    assert list(out["dv_mps"]) == [0.015] and list(out["kind"]) == ["unknown"]
    assert "not burns (no propulsion)" in notes[-1]
