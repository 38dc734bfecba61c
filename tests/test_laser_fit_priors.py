"""The tracking fit inside physical bounds: priors on scale factors and range biases, and the Earth-fixed frame.

* A scale factor with a prior is the information-weighted mean of the data's estimate and the prior
  (linear Gaussian estimation: 1/σ² = 1/σ_data² + 1/σ_prior²), checked against the fit without prior.
* A range-bias prior constrains each station's departure from the stations' common bias, never the
  common part (the target's centre-of-mass offset): a 0.3 m bias common to three stations is recovered
  under a 1 cm prior.
* The stations' Earth-fixed frame includes polar motion: ``earth_rotation_matrices`` agrees with
  astropy's ITRS→GCRS transformation (an independent implementation) to millimetres at a station.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from astropy import units as u
from astropy.coordinates import GCRS, ITRS, CartesianRepresentation
from astropy.time import Time

from abrupt.model.orbit import ForceModel, coe_to_rv, propagate
from abrupt.model.orbit.batch_fit import BatchFitConfig, fit_orbit
from abrupt.model.stations import Station
from abrupt.model.tracking_measurements import TrackingArrays, earth_rotation_matrices, predict_measurement

MU = 3.986004418e14
EPOCH = np.datetime64("2024-01-01T00:00:00", "ns")


def _ranges(
    truth: ForceModel, stations: dict[str, Station], bias_m: dict[str, float], seed: int
) -> tuple[TrackingArrays, np.ndarray]:
    """One day of 1 m ranges every 20 s above 10° to a 350 km orbit, each station biased by ``bias_m``."""
    x0 = coe_to_rv(6378e3 + 350e3, 0.001, math.radians(51.6), 0.3, 0.2, 0.1, MU)
    t = np.arange(0.0, 86_400.0, 20.0)
    states = propagate(x0, t, force=truth)
    rng = np.random.default_rng(seed)
    rows = []
    c_fi = earth_rotation_matrices(t)
    for name, st in stations.items():
        for k in range(t.size):
            y, _ = predict_measurement(states[k], c_fi[k], st.position_ecef_m, st.ecef_to_sez)
            if y[2] > math.radians(10.0):
                rows.append((t[k], name, y[0] + bias_m.get(name, 0.0) + rng.normal(0.0, st.sigma_range_m)))
    frame = pd.DataFrame(rows, columns=["t", "station", "range_m"])
    frame["time_utc"] = EPOCH + (frame["t"] * 1e9).astype("timedelta64[ns]")
    for col in ("azimuth_rad", "elevation_rad", "range_rate_mps"):
        frame[col] = np.nan
    start = x0 + np.r_[rng.normal(0, 30.0, 3), rng.normal(0, 0.03, 3)]
    return TrackingArrays(frame.drop(columns="t"), stations, epoch_utc=EPOCH), start


def test_a_scale_prior_gives_the_information_weighted_mean_of_data_and_prior() -> None:
    model = ForceModel(mu_m3_s2=MU, zonal_degree=2, drag="exponential", drag_area_m2=4.0, mass_kg=100.0)
    truth = ForceModel(**{**model.__dict__, "drag_scale": 1.5})
    stations = {
        "A": Station("A", 40.0, 0.0, 100.0, sigma_range_m=1.0),
        "B": Station("B", -30.0, 150.0, 100.0, sigma_range_m=1.0),
    }
    data, start = _ranges(truth, stations, {}, seed=3)
    cfg = BatchFitConfig(force=model, estimate_scales=("drag_scale",), max_step_s=20.0)
    free = fit_orbit(data, start, config=cfg)
    s_data = free.sigma("drag_scale")
    s_prior = s_data  # equal weights: the estimate lies halfway between the data's and the prior's (1)
    held = fit_orbit(data, start, config=BatchFitConfig(**{**cfg.__dict__, "scale_priors": (("drag_scale", s_prior),)}))
    assert free.converged and held.converged
    expected = (free.scale_factors["drag_scale"] / s_data**2 + 1.0 / s_prior**2) / (1 / s_data**2 + 1 / s_prior**2)
    # within the Gauss-Newton stopping tolerance (a few data σ; the prior moved the estimate by 4000 of them)
    assert held.scale_factors["drag_scale"] == pytest.approx(expected, abs=4 * s_data)
    assert held.sigma("drag_scale") == pytest.approx(s_data / math.sqrt(2.0), rel=0.05)
    # the data alone put the scale far from 1: the prior is what moved it
    assert abs(free.scale_factors["drag_scale"] - 1.0) > 10 * s_data


def test_a_range_bias_prior_leaves_the_common_bias_free() -> None:
    """Three stations all ranging 0.3 m long (a centre-of-mass offset): under a 1 cm prior on each
    station's departure from the common bias the fit still finds 0.3 m at every station."""
    two_body = ForceModel(mu_m3_s2=MU)
    stations = {
        n: Station(n, lat, lon, 100.0, sigma_range_m=0.01)
        for n, lat, lon in (("A", 40.0, 0.0), ("B", -30.0, 150.0), ("C", 10.0, -70.0))
    }
    data, start = _ranges(two_body, stations, dict.fromkeys(stations, 0.3), seed=5)
    cfg = BatchFitConfig(
        force=two_body, estimate_range_bias=True, max_step_s=20.0, integrator="rk8", range_bias_prior_m=0.01
    )
    fit = fit_orbit(data, start, config=cfg)
    assert fit.converged
    for name in stations:
        assert fit.range_bias_m[name] == pytest.approx(0.3, abs=4 * fit.sigma(f"range_bias[{name}]") + 0.002)
    assert fit.rms_white < 1.2


@pytest.mark.parametrize("when", ["2018-06-14T06:00:00", "2024-03-01T18:30:00"])
def test_the_earth_fixed_frame_includes_polar_motion(when: str) -> None:
    """A station's GCRF position from ``earth_rotation_matrices`` against astropy's ITRS→GCRS (which
    applies UT1−UTC, precession-nutation and polar motion from the same IERS table): millimetres; without
    polar motion they would differ by metres (0.3 arcsecond at the Earth's radius is 9 m)."""
    site = Station("GRZL", 47.0671, 15.4933, 539.0).position_ecef_m
    epoch = np.datetime64(when, "ns")
    c_fi = earth_rotation_matrices(np.zeros(1), model="iers", epoch_utc=epoch)[0]
    ours = c_fi.T @ site
    t = Time(epoch, scale="utc", format="datetime64")
    itrs = ITRS(CartesianRepresentation(*(site * u.m)), obstime=t)
    theirs = itrs.transform_to(GCRS(obstime=t)).cartesian.xyz.to_value(u.m)
    assert np.linalg.norm(ours - theirs) < 0.02
