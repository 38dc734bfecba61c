"""Light time, troposphere, time biases, scale factors and robustness of the tracking fit.

The radio fit's two-way range and downleg angles (:func:`predict_measurement_light_time`, a first-order
closed form) are checked against the iterative two-way light-time solution of the laser reduction
(:func:`abrupt.model.light_time.two_way_range_m`) and against the directly computed downleg direction,
for a transfer orbit seen from a ground station (the W3B case: light time ≈ 0.1 s, range rate km/s).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import CubicSpline

from abrupt.model.light_time import two_way_range_m
from abrupt.model.orbit import ForceModel, coe_to_rv, propagate
from abrupt.model.orbit.batch_fit import BatchFitConfig, fit_orbit, radio_range_delay_m
from abrupt.model.range_reduction import standard_meteorology
from abrupt.model.stations import Station, ascension
from abrupt.model.tracking_measurements import (
    TrackingArrays,
    earth_rotation_matrices,
    predict_measurement,
    predict_measurement_light_time,
)
from abrupt.model.troposphere import saastamoinen_zenith_delay_m, water_vapour_pressure_hpa
from abrupt.simulate.tracking import TrackingScenario, simulate_tracking

MU = 3.986004418e14
TWO_BODY = ForceModel(mu_m3_s2=MU)
STATION = Station("Fucino", 41.9774962512, 13.6004229863, 671.35)


def _geometry():  # type: ignore[no-untyped-def]
    """A GTO (perigee 250 km, apogee 35,800 km) and receive times when the station sees it."""
    a = 6378e3 + (250e3 + 35_800e3) / 2.0
    e = (35_800e3 - 250e3) / (2.0 * a)
    x0 = coe_to_rv(a, e, math.radians(7.0), math.radians(20.0), math.radians(178.0), math.radians(150.0), MU)
    t_fine = np.arange(0.0, 40_000.0, 0.5)
    states = propagate(x0, t_fine, force=TWO_BODY)
    c_fi = earth_rotation_matrices(t_fine)
    site = STATION.position_ecef_m
    sez = np.einsum("ij,njk,nk->ni", STATION.ecef_to_sez, c_fi, states[:, :3]) - STATION.ecef_to_sez @ site
    elevation = np.arcsin(sez[:, 2] / np.linalg.norm(sez, axis=1))
    visible = np.flatnonzero(elevation > math.radians(10.0))
    receive = t_fine[visible[:: max(1, visible.size // 12)]][1:-1]
    return t_fine, states, receive


def _interpolate(t_fine, states, t):  # type: ignore[no-untyped-def]
    return np.column_stack([np.interp(t, t_fine, states[:, k]) for k in range(3)])


def test_two_way_range_and_downleg_angles_match_the_iterative_solution() -> None:
    t_fine, states, receive = _geometry()

    spline = CubicSpline(t_fine, states[:, :3], axis=0)

    def sat(t: np.ndarray) -> np.ndarray:
        return np.asarray(spline(np.atleast_1d(t)))

    def sta(t: np.ndarray) -> np.ndarray:
        c = earth_rotation_matrices(np.atleast_1d(t))
        return np.einsum("nji,j->ni", c, STATION.position_ecef_m)

    exact, t_bounce = two_way_range_m(receive, sat, sta, shapiro=False)
    c_r = earth_rotation_matrices(receive)
    corrections = []
    for k, t_r in enumerate(receive):
        x = np.concatenate([sat(np.array([t_r]))[0], np.asarray(spline(t_r, 1))])
        y_lt, h_lt = predict_measurement_light_time(x, c_r[k], STATION.position_ecef_m, STATION.ecef_to_sez)
        y_inst, _ = predict_measurement(x, c_r[k], STATION.position_ecef_m, STATION.ecef_to_sez)
        assert y_lt[0] == pytest.approx(exact[k], abs=5e-3)  # metres of a ~40,000 km range
        corrections.append(abs(y_inst[0] - exact[k]))
        # downleg: the direction from the station at t_r to the satellite at the bounce time
        los = c_r[k] @ sat(np.array([t_bounce[k]]))[0] - STATION.position_ecef_m
        s, e, z = STATION.ecef_to_sez @ los
        azimuth = math.atan2(e, -s) % (2.0 * math.pi)
        elevation = math.asin(z / math.sqrt(s * s + e * e + z * z))
        assert y_lt[1] == pytest.approx(azimuth, abs=2e-7)
        assert y_lt[2] == pytest.approx(elevation, abs=2e-7)
        # Jacobian against central differences of the same function
        for j, step in ((0, 1.0), (4, 0.1)):
            dx = np.zeros(6)
            dx[j] = step
            yp, _ = predict_measurement_light_time(x + dx, c_r[k], STATION.position_ecef_m, STATION.ecef_to_sez)
            ym, _ = predict_measurement_light_time(x - dx, c_r[k], STATION.position_ecef_m, STATION.ecef_to_sez)
            np.testing.assert_allclose(h_lt[:3, j], (yp[:3] - ym[:3]) / (2 * step), rtol=1e-5, atol=1e-9)
    # the instantaneous model is wrong by metres to hundreds of metres here: the test can fail
    assert max(corrections) > 20.0


def test_radio_troposphere_is_the_saastamoinen_zenith_delay_mapped_to_the_elevation() -> None:
    meas = pd.DataFrame(
        {
            "time_utc": pd.to_datetime(["2010-11-02T03:00:00", "2010-11-02T03:01:00"]),
            "station": ["Fucino", "Fucino"],
            "range_m": [3.8e7, 3.8e7],
            "azimuth_rad": [np.nan, np.nan],
            "elevation_rad": [np.nan, np.nan],
            "range_rate_mps": [np.nan, np.nan],
        }
    )
    data = TrackingArrays(meas, {"Fucino": STATION})
    delay = radio_range_delay_m(data, np.radians([90.0, 10.0]))
    p, t, rh = standard_meteorology(STATION.altitude_m)
    hydro, wet = saastamoinen_zenith_delay_m(
        math.radians(STATION.latitude_deg), STATION.altitude_m, p, t, water_vapour_pressure_hpa(t, rh)
    )
    zenith = float(hydro + wet)
    assert 2.0 < zenith < 2.6  # metres at 671 m altitude (Saastamoinen 1972: 2.3 m at sea level)
    assert delay[0] == pytest.approx(zenith, rel=2e-3)  # the Chao mapping is 1 at the zenith
    # at 10° the Earth's curvature makes the mapping 5.5-5.6, below the flat-Earth 1/sin(10°) = 5.76
    # (the Chao, Marini and Niell mappings all give about 5.5-5.6 there)
    assert 5.45 < delay[1] / zenith < 5.65


def test_a_station_time_bias_is_recovered_by_the_batch_fit() -> None:
    """One of two stations tags its measurements 20 ms late (tens of metres of range on a LEO pass; a
    common offset of all stations is an along-track shift of the orbit and cannot be seen). The fit
    recovers the offset within its stated σ; without the parameter the residuals are far from white."""

    malindi = Station("MALINDI", -2.99, 40.19, 12.0, elevation_mask_deg=1.0)
    sim = simulate_tracking(TrackingScenario(stations=(ascension(1.0), malindi), cadence_s=10.0), seed=4)
    late_s = 0.02
    meas = sim.measurements.copy()
    late = meas["station"] == "MALINDI"
    meas.loc[late, "time_utc"] = meas.loc[late, "time_utc"] + pd.Timedelta(seconds=late_s)
    data = TrackingArrays(meas, {"MALINDI": malindi}, epoch_utc=sim.epoch_utc)
    rng = np.random.default_rng(9)
    x0 = sim.initial_state + np.r_[rng.normal(0, 50.0, 3), rng.normal(0, 0.05, 3)]
    fit = fit_orbit(data, x0, config=BatchFitConfig(estimate_time_bias=("MALINDI",)))
    assert fit.converged
    sigma = fit.sigma("time_bias[MALINDI]")
    assert sigma < late_s / 10
    assert fit.time_bias_s["MALINDI"] == pytest.approx(late_s, abs=4 * sigma)
    assert fit.rms_white == pytest.approx(1.0, abs=0.1)
    plain = fit_orbit(data, x0, config=BatchFitConfig())
    assert plain.rms_white > 1.5


def test_the_batch_fit_estimates_a_drag_scale_factor() -> None:
    """Ranges from two stations to a 350 km orbit whose drag is 1.5 times the model's: the fit with
    ``estimate_scales=("drag_scale",)`` recovers 1.5 within its σ, and its residuals are white; with
    the scale fixed at 1 the residuals are not."""

    model = ForceModel(mu_m3_s2=MU, zonal_degree=2, drag="exponential", drag_area_m2=4.0, mass_kg=100.0)
    truth = ForceModel(**{**model.__dict__, "drag_scale": 1.5})
    x0 = coe_to_rv(6378e3 + 350e3, 0.001, math.radians(51.6), 0.3, 0.2, 0.1, MU)
    t = np.arange(0.0, 86_400.0, 20.0)
    states = propagate(x0, t, force=truth)
    stations = {
        "A": Station("A", 40.0, 0.0, 100.0, sigma_range_m=1.0),
        "B": Station("B", -30.0, 150.0, 100.0, sigma_range_m=1.0),
    }
    rng = np.random.default_rng(3)
    rows = []
    c_fi = earth_rotation_matrices(t)
    for name, st in stations.items():
        for k in range(t.size):
            y, _ = predict_measurement(states[k], c_fi[k], st.position_ecef_m, st.ecef_to_sez)
            if y[2] > math.radians(10.0):
                rows.append((t[k], name, y[0] + rng.normal(0.0, 1.0)))
    frame = pd.DataFrame(rows, columns=["t", "station", "range_m"])
    epoch = np.datetime64("2024-01-01T00:00:00", "ns")
    frame["time_utc"] = epoch + (frame["t"] * 1e9).astype("timedelta64[ns]")
    for col in ("azimuth_rad", "elevation_rad", "range_rate_mps"):
        frame[col] = np.nan
    data = TrackingArrays(frame.drop(columns="t"), stations, epoch_utc=epoch)
    start = x0 + np.r_[rng.normal(0, 30.0, 3), rng.normal(0, 0.03, 3)]
    cfg = BatchFitConfig(force=model, estimate_scales=("drag_scale",), max_step_s=20.0)
    fit = fit_orbit(data, start, config=cfg)
    assert fit.converged
    sigma = fit.sigma("drag_scale")
    assert sigma < 0.05
    assert fit.scale_factors["drag_scale"] == pytest.approx(1.5, abs=4 * sigma)
    assert fit.rms_white == pytest.approx(1.0, abs=0.1)
    fixed = fit_orbit(data, start, config=BatchFitConfig(force=model, max_step_s=20.0))
    assert fixed.rms_white > 3.0


def test_the_fit_converges_from_an_apriori_orbit_twenty_kilometres_off() -> None:
    """Plain Gauss-Newton overshoots from 20 km / 20 m/s off (the linearisation fails and the iteration
    blows up to NaN); with step halving the fit reaches the same solution as from a close start."""

    sim = simulate_tracking(TrackingScenario(stations=(ascension(1.0),), cadence_s=10.0), seed=4)
    data = TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    rng = np.random.default_rng(1)
    near = fit_orbit(
        data, sim.initial_state + np.r_[rng.normal(0, 5e3, 3), rng.normal(0, 5.0, 3)], config=BatchFitConfig()
    )
    far = fit_orbit(
        data, sim.initial_state + np.r_[rng.normal(0, 2e4, 3), rng.normal(0, 20.0, 3)], config=BatchFitConfig()
    )
    assert near.converged and far.converged
    assert np.linalg.norm(far.x0[:3] - near.x0[:3]) < 0.1  # m
    assert far.rms_white == pytest.approx(near.rms_white, rel=1e-6)
