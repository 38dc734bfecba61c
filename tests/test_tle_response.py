"""Element sets as fits over their span: the fraction of a burn a set carries, and burns timed from
the sets that blend them.

Independent truths: (1) the fraction is checked against a least-squares line fitted numerically to a
densely sampled hinge (numpy ``polyfit``), not against the closed form; (2) a simulated history
(:func:`abrupt.simulate.tle_null.simulate_null_history`) whose sets after each burn are replaced by
such numerical fits over a 4-day span, with burns at known times.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from abrupt.detect.tle.detectors import TleMeanElements
from abrupt.detect.tle.elements import mean_element_series
from abrupt.detect.tle.response import span_fraction
from abrupt.detect.tle.timing import phase_kinks, smoothed_hinge_d
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, ElementHistory
from abrupt.simulate.tle_null import EPOCH0, NullHistorySpec, history_from_series, simulate_null_history
from abrupt.thresholds import FalseAlarmBudget

SPAN_DAYS = 4.0


def _fitted_fraction(x_days: float, span_days: float) -> float:
    """Slope of a least-squares line through ``max(0, t − t_b)`` sampled over the span ending
    ``x_days`` after the burn (numerically)."""
    t = np.linspace(x_days - span_days, x_days, 2001)
    return float(np.polyfit(t, np.maximum(t, 0.0), 1)[0])


@pytest.mark.parametrize("x_days", [-1.0, 0.0, 0.4, 1.0, 2.0, 3.3, 4.0, 6.0])
def test_fraction_of_a_burn_a_set_carries_is_the_least_squares_slope(x_days: float) -> None:
    expected = _fitted_fraction(x_days, SPAN_DAYS)
    assert span_fraction(np.array([x_days * 86400.0]), SPAN_DAYS * 86400.0)[0] == pytest.approx(expected, abs=2e-3)


def _fitted_phase(x_days: float, span_days: float) -> float:
    """Value at the span's end (the set's epoch) of that least-squares line (days × Δn)."""
    t = np.linspace(x_days - span_days, x_days, 2001)
    slope, intercept = np.polyfit(t, np.maximum(t, 0.0), 1)
    return float(slope * x_days + intercept)


@pytest.mark.parametrize("span_days", [0.0, 2.0, 7.0])
@pytest.mark.parametrize("x_days", [-1.0, 0.0, 0.5, 1.5, 3.0, 6.9, 7.0, 9.0])
def test_along_track_angle_a_set_shows_is_the_least_squares_line_at_its_epoch(x_days: float, span_days: float) -> None:
    """The smoothed hinge the burn timing fits is the value at the epoch of a least-squares line through
    the kinked along-track track over the set's span (numerical fit; a sharp hinge for a span of 0)."""
    expected = _fitted_phase(x_days, span_days) if span_days > 0 else max(x_days, 0.0)
    assert float(smoothed_hinge_d(np.array([x_days]), span_days)[0]) == pytest.approx(expected, abs=2e-3)


def _blended_history(
    burn_days: list[float], dvs: list[float], seed: int, span_days: float = SPAN_DAYS
) -> ElementHistory:
    """A maneuver-free simulated history plus in-track burns whose sets are least-squares fits over
    ``SPAN_DAYS``: ``a`` and the e-vector carry the fitted fraction of each burn, the along-track phase
    the fitted line's value at the epoch (minus what the sets' own blended rates integrate)."""
    spec = NullHistorySpec(altitude_km=800.0, sets_per_day=1.0, years=1.1, bad_set_probability=0.0, seed=seed)
    base = simulate_null_history(spec)
    s = mean_element_series(base, "leo")
    t_days = s["t_s"] / 86400.0
    a0 = float(np.median(s["a_m"]))
    v = float(np.sqrt(MU_EARTH_WGS72_M3_S2 / a0))
    n0 = v / a0
    series = {
        "a_m": s["a_m"].copy(),
        "ex": s["ex"].copy(),
        "ey": s["ey"].copy(),
        "n1_rad": s["i_rad"].copy(),
        "n2_rad": s["raan_resid_sin_i_rad"].copy(),
        "u_m": s["u_m"].copy(),
    }
    rng = np.random.default_rng([seed, 3])
    for day, dv in zip(burn_days, dvs, strict=True):
        x = t_days - day
        frac = np.array([_fitted_fraction(xi, span_days) for xi in x])
        phase = np.array([_fitted_phase(xi, span_days) if xi > 0 else 0.0 for xi in x])  # days
        da = 2.0 * a0 * dv / v
        dn = -1.5 * n0 * da / a0  # [rad/s]
        u_arg = float(rng.uniform(0.0, 2.0 * np.pi))
        series["a_m"] += da * frac
        series["ex"] += 2.0 * dv / v * np.cos(u_arg) * frac
        series["ey"] += 2.0 * dv / v * np.sin(u_arg) * frac
        # the residual the detector reads: the fitted angle minus what the blended rates integrate
        integrated = np.concatenate([[0.0], np.cumsum(0.5 * (frac[1:] + frac[:-1]) * np.diff(t_days))])
        series["u_m"] += a0 * dn * 86400.0 * (phase - integrated)
    return history_from_series(t_days, series, "leo", norad=99911)


def test_burns_blended_over_days_of_fit_span_are_timed_from_the_blends() -> None:
    """Eight 10-20 cm/s in-track burns 45 days apart in an 800 km history at one set a day whose sets
    are fits over 4 days: a set carries the fitted fraction of a burn, so the step the detector sees
    comes one to three sets after it. Each burn is found once and timed within 0.35 days, and at
    least 6 of 8 stated intervals hold the true time."""
    rng = np.random.default_rng(8)
    burn_days = [40.0 + 45.0 * k + float(rng.uniform(0.0, 1.0)) for k in range(8)]
    dvs = [float(rng.choice([-1.0, 1.0]) * rng.uniform(0.10, 0.20)) for _ in burn_days]
    h = _blended_history(burn_days, dvs, 21)
    ev = TleMeanElements().detect(h, FalseAlarmBudget(1.0, "year")).events
    ev = ev.loc[(ev["kind"] == "maneuver") & (ev["statistic"] >= ev["threshold"])]

    def days(col: str) -> np.ndarray:
        ts = pd.to_datetime(ev[col].astype(str), format="ISO8601").dt.tz_localize(None) - pd.Timestamp(EPOCH0)
        return ts.dt.total_seconds().to_numpy() / 86400.0

    t_days, lo_d, hi_d = days("time_utc"), days("interval_start_utc"), days("interval_end_utc")
    covered = 0
    for day in burn_days:
        near = np.flatnonzero(np.abs(t_days - day) < 3.0)
        assert near.size == 1, (day, t_days)
        assert abs(t_days[near[0]] - day) < 0.35, (day, t_days[near[0]])
        covered += int(lo_d[near[0]] <= day <= hi_d[near[0]])
    assert covered >= 6


def _phase_history(kind: str, seed: int) -> tuple[ElementHistory, int]:
    """Daily sets of an 800 km orbit whose along-track phase either bends at day 20.4 (an in-track burn,
    2 km/day of drift, as sets fitted over 6 days show it) or jumps by 5 km there (an opposed pair
    between two sets), with 30 m of per-set phase noise; and the gap just after the change."""
    rng = np.random.default_rng(seed)
    t_days = np.arange(40.0) + rng.uniform(-0.2, 0.2, 40)
    x = t_days - 20.4
    signal = 2000.0 * smoothed_hinge_d(x, 6.0) if kind == "bend" else np.where(x > 0, 5000.0, 0.0)
    series = {
        "a_m": np.full(40, 7178.0e3),
        "ex": np.full(40, 1.0e-3),
        "ey": np.zeros(40),
        "n1_rad": np.full(40, np.radians(98.6)),
        "n2_rad": np.zeros(40),
        "u_m": signal + rng.normal(0.0, 30.0, 40),
    }
    return history_from_series(t_days, series, "leo", norad=99912), int(np.searchsorted(t_days, 20.4))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_phase_that_bends_is_a_burn_and_one_that_jumps_is_a_pair(seed: int) -> None:
    """``phase_kinks`` tells the two shapes of a phase-only detection apart on the sets themselves."""
    for kind, expected in (("bend", True), ("jump", False)):
        h, gap = _phase_history(kind, seed)
        t_s = mean_element_series(h, "leo")["t_s"]
        assert phase_kinks(h, gap, 8, t_s, 3) is expected, kind
