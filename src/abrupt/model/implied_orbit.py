"""The orbit implied by a station's ranges and angles: a range in the wrong unit cannot be accepted.

A range alone is any number a satellite above the station could have; a range with its azimuth and
elevation is a position, and two positions of one pass a velocity. Vis-viva (v² = μ(2/r − 1/a); Vallado
2013, Eq. 1-31) bounds the speed of every Earth satellite at radius r on both sides:

* at least the apogee speed of an orbit whose perigee grazes the surface (r_p = R_E):
  v_min(r) = √(2μR_E / (r (r + R_E))) — anything slower falls into the Earth;
* less than the escape speed v_esc(r) = √(2μ/r) — anything faster leaves it.

Ranges ten times too short (km written as 10 km, metres as decametres) place the satellite a few thousand
kilometres above the station, turning with the Earth at about 0.5 km/s where v_min is 6-7 km/s: one tenth
of the least orbital speed. Ranges ten times too long put it at lunar distances moving at tens of km/s,
many times the escape speed there. The real arc of W3B (a transfer orbit with its perigee 220 km above
the surface, the hardest case: its apogee speed is only 1.5 % above v_min) keeps every station's median
speed ratio above one.

Noise: each velocity is taken over the shortest baseline whose noise (from the station's stated range and
angle sigmas) is about :data:`VELOCITY_NOISE` of the circular speed at that radius, and at most a
twelfth of the circular period (the chord's speed is then within 1.2 % of the arc's). Noise makes a speed
larger on average, never smaller, so it cannot cause the "too slow" refusal. A station is refused only
when its median speed ratio is beyond the bound by more than three standard errors of that median (the
ratios' robust standard deviation, 1.4826 × their median absolute deviation, × 1.2533/√n for n ratios).
Satellites only: an Earth-escape trajectory (a departing probe) is refused. Angles are interpolated
linearly to the range epochs between angle samples at most that twelfth of a period apart.

A station without angles gives no position; its ranges are held against the set-up file's a-priori orbit
instead (:func:`check_ranges_against_orbit`). The batch fit starts from that orbit and linearises around
it, so its ranges must be of the size of the measured ones: a station whose median ratio of measured to
predicted range is beyond a factor of two (position errors as large as the distance itself, where no
linearised fit starts) is refused, naming the two causes it has met: a unit error, or the a-priori of
another satellite. W3B's a-priori (two-body from the set-up's state) predicts each of its 182 ranges over
the 15.8-hour arc within 0.11 % (22 km); its ranges ×0.1 are a tenth of the prediction.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from abrupt.errors import InputError
from abrupt.model.orbit import MU_EARTH_M3_S2, ForceModel, propagate
from abrupt.model.stations import WGS84_A_M
from abrupt.model.tracking_measurements import TrackingArrays, predict_many
from abrupt.thresholds.noise import robust_scale
from abrupt.types import FloatArray

MEDIAN_EFFICIENCY = 1.2533  # [-] standard error of a Gaussian sample's median × √n / σ (√(π/2))
SIGMAS = 3.0  # [-] standard errors of the median beyond a bound before a station is refused
VELOCITY_NOISE = 0.05  # [-] a velocity's noise (stated sigmas) as a fraction of the circular speed
PERIOD_FRACTION = 1.0 / 12.0  # [-] longest baseline: 30 degrees of a circular orbit at that radius
MIN_PAIRS = 3  # velocities a verdict needs
A_PRIORI_FACTOR = 2.0  # [-] measured/predicted range beyond which no linearised fit starts
A_PRIORI_RANGES = 200  # ranges (evenly spread over the file) held against the a-priori orbit


@dataclass(frozen=True)
class ImpliedSpeeds:
    """One station's implied speeds as ratios to the vis-viva bounds: medians and standard errors."""

    station: str
    pairs: int
    to_minimum: float  # median of v / v_min(r)
    to_minimum_error: float
    to_escape: float  # median of v / v_esc(r)
    to_escape_error: float

    @property
    def too_slow(self) -> bool:
        """Slower than any orbit that clears the surface, by more than three standard errors."""
        return self.to_minimum + SIGMAS * self.to_minimum_error < 1.0

    @property
    def too_fast(self) -> bool:
        """Faster than the escape speed, by more than three standard errors."""
        return self.to_escape - SIGMAS * self.to_escape_error > 1.0


def implied_speeds(data: TrackingArrays) -> dict[str, ImpliedSpeeds]:
    """Per station with ranges and angles (at least :data:`MIN_PAIRS` velocities), its speed ratios.

    Ranges have the station's modelled range bias removed; angles are the azimuth and elevation [rad] as
    given (refraction-corrected where the caller corrected them). Stations without both are left out.
    """
    out: dict[str, ImpliedSpeeds] = {}
    for name, (r, v) in implied_states(data).items():
        if len(r) < MIN_PAIRS:
            continue
        radius = np.linalg.norm(r, axis=1)
        speed = np.linalg.norm(v, axis=1)
        v_min = np.sqrt(2.0 * MU_EARTH_M3_S2 * WGS84_A_M / (radius * (radius + WGS84_A_M)))
        slow = np.where(radius > WGS84_A_M, speed / v_min, 0.0)  # a position inside the Earth: no orbit
        fast = speed / np.sqrt(2.0 * MU_EARTH_M3_S2 / radius)
        out[name] = ImpliedSpeeds(name, len(r), *_median_error(slow), *_median_error(fast))
    return out


def implied_states(data: TrackingArrays) -> dict[str, tuple[FloatArray, FloatArray]]:
    """Per station, the inertial positions [m] (n,3) and velocities [m/s] (n,3) its ranges and angles
    imply: chord mid-points and chord velocities (module docstring); stations without both are empty."""
    names = np.asarray(data.station_names)
    return {
        name: _velocities(*_positions(data, np.flatnonzero(names == name))) for name in sorted(set(data.station_names))
    }


def check_implied_speeds(data: TrackingArrays, file: str | Path) -> None:
    """Raise :class:`InputError` naming ``file`` and the station whose ranges and angles imply a speed no
    Earth satellite has (slower than an orbit that clears the surface, or faster than escape)."""
    for s in implied_speeds(data).values():
        where = f"station {s.station}: its ranges and angles ({s.pairs} velocities) imply a speed"
        if s.too_slow:
            raise InputError(
                f"{where} of {s.to_minimum:.2f} (± {s.to_minimum_error:.2f}) times the least speed of an orbit "
                "that clears the Earth's surface at that radius: no satellite moves so; ranges in the wrong unit?",
                file=file,
                column="range",
            )
        if s.too_fast:
            raise InputError(
                f"{where} of {s.to_escape:.2f} (± {s.to_escape_error:.2f}) times the escape speed at that "
                "radius: no satellite moves so; ranges in the wrong unit?",
                file=file,
                column="range",
            )


def check_ranges_against_orbit(
    data: TrackingArrays, x0_m_mps: FloatArray, file: str | Path, *, mu_m3_s2: float = MU_EARTH_M3_S2
) -> None:
    """Raise :class:`InputError` naming ``file`` and the station whose ranges (bias removed) are, in their
    median, more than :data:`A_PRIORI_FACTOR` times shorter or longer than those of the two-body orbit
    from ``x0_m_mps`` (m, m/s, inertial, at ``data.epoch_utc``). Ranges before the epoch are not judged."""
    ranged = np.flatnonzero(np.isfinite(data.y[:, 0]) & (data.t_s >= 0.0))
    if ranged.size == 0:
        return
    rows = ranged[np.unique(np.linspace(0, ranged.size - 1, min(ranged.size, A_PRIORI_RANGES)).astype(int))]
    states = propagate(np.asarray(x0_m_mps, float), data.t_s[rows], force=ForceModel(mu_m3_s2=mu_m3_s2), rtol=1e-10)
    predicted = np.array([predict_many(states[k : k + 1], data.c_fi[i : i + 1], data.site[i], data.c_sf[i])[0, 0]
                          for k, i in enumerate(rows)])  # fmt: skip
    ratio = (data.y[rows, 0] - data.range_bias_m[rows]) / predicted
    names = np.asarray(data.station_names)[rows]
    for name in sorted(set(names)):
        median = float(np.median(ratio[names == name]))
        if not 1.0 / A_PRIORI_FACTOR <= median <= A_PRIORI_FACTOR:
            raise InputError(
                f"station {name}: its ranges are {median:.3g} times those of the set-up's a-priori orbit (median "
                f"of {int((names == name).sum())}): ranges in the wrong unit, or an a-priori orbit of another "
                "satellite?",
                file=file,
                column="range",
            )


def _positions(data: TrackingArrays, rows: np.ndarray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Inertial positions [m] at the station's range epochs whose angles can be interpolated, their
    epochs [s] and their stated position noise [m]."""
    t, y, sigma = data.t_s[rows], data.y[rows], data.sigma[rows]
    angle = np.isfinite(y[:, 1]) & np.isfinite(y[:, 2])
    ranged = np.flatnonzero(np.isfinite(y[:, 0]))
    if angle.sum() < 1 or ranged.size < 2:
        return np.empty((0, 3)), np.empty(0), np.empty(0)
    ta, az, el = t[angle], np.unwrap(y[angle, 1]), y[angle, 2]
    tr = t[ranged]
    k = np.searchsorted(ta, tr, side="right")
    lo, hi = np.clip(k - 1, 0, ta.size - 1), np.clip(k, 0, ta.size - 1)
    span = ta[hi] - ta[lo]
    w = np.divide(tr - ta[lo], span, out=np.zeros_like(tr), where=span > 0)
    a = az[lo] + w * (az[hi] - az[lo])
    e = el[lo] + w * (el[hi] - el[lo])
    rho = y[ranged, 0] - data.range_bias_m[rows][ranged]
    # South-East-Zenith components (azimuth from North through East: β = atan2(ρ_E, −ρ_S))
    sez = rho[:, None] * np.column_stack([-np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    ecef = data.site[rows][ranged] + np.einsum("nji,nj->ni", data.c_sf[rows][ranged], sez)
    inertial = np.einsum("nji,nj->ni", data.c_fi[rows][ranged], ecef)
    s = sigma[ranged]
    noise = np.sqrt(s[:, 0] ** 2 + (rho * np.cos(e) * s[:, 1]) ** 2 + (rho * s[:, 2]) ** 2)
    # an angle interpolated over no more than the longest baseline (or measured at the range epoch)
    inside = (ta[lo] == tr) | ((k > 0) & (k < ta.size) & (span <= _longest_baseline_s(inertial)))
    return inertial[inside], tr[inside], noise[inside]


def _longest_baseline_s(r: FloatArray) -> FloatArray:
    """A twelfth of the circular period at each position's radius [s]."""
    radius = np.linalg.norm(r, axis=1)
    return np.asarray(PERIOD_FRACTION * 2.0 * np.pi * np.sqrt(radius**3 / MU_EARTH_M3_S2))


def _velocities(r: FloatArray, t: FloatArray, noise: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Mid-point positions [m] and chord velocities [m/s]: from each epoch to the first one at least the
    baseline later over which the stated noise is :data:`VELOCITY_NOISE` of the circular speed, when that
    partner is within the longest baseline and its own noise keeps the chord within that fraction."""
    radius = np.linalg.norm(r, axis=1)
    allowed = VELOCITY_NOISE * np.sqrt(MU_EARTH_M3_S2 / np.maximum(radius, 1.0))  # [m/s]
    need = np.maximum(np.sqrt(2.0) * noise / allowed, 1e-6)  # [s] the baseline for two equal noises
    j = np.searchsorted(t, t + need, side="left")
    ok = j < t.size
    i, j = np.flatnonzero(ok), j[ok]
    dt = t[j] - t[i]
    ok = (dt <= _longest_baseline_s(r)[i]) & (np.hypot(noise[i], noise[j]) <= allowed[i] * dt)
    i, j, dt = i[ok], j[ok], dt[ok]
    return 0.5 * (r[i] + r[j]), (r[j] - r[i]) / dt[:, None]


def _median_error(x: FloatArray) -> tuple[float, float]:
    """The median of ``x`` and its standard error from the robust spread of ``x``."""
    med = float(np.median(x))
    return med, MEDIAN_EFFICIENCY * float(robust_scale(x)) / float(np.sqrt(x.size))
