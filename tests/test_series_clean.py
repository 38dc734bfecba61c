"""The series and clean stages: chunking with carry-over, telemetry row ranges, robust scale."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from abrupt.detect.attitude.change_detection import WindowConfig, sliding_statistic
from abrupt.errors import RepairLog
from abrupt.series import Chunk, Telemetry, chunk_rows, split_at_gaps, telemetry_chunks
from abrupt.thresholds.noise import robust_noise_sigma, robust_scale


def _telemetry(n: int, rate_hz: float = 10.0, gap_at: int | None = None) -> Telemetry:
    t_ns = np.arange(n, dtype=np.int64) * round(1e9 / rate_hz)
    if gap_at is not None:
        t_ns[gap_at:] += 10 * round(1e9 / rate_hz)
    t_s = (t_ns - t_ns[0]) / 1e9
    interval, gaps, segments = split_at_gaps(t_s)
    rng = np.random.default_rng(1)
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    return Telemetry(
        time=np.datetime64("2024-01-01T00:00:00", "ns") + t_ns.astype("timedelta64[ns]"),
        t_s=t_s,
        quaternion_BN=q,
        body_rate_rad_s=rng.normal(size=(n, 3)) * 1e-5,
        wheel_speed_rad_s=np.zeros((n, 0)),
        sample_interval_s=interval,
        segments=segments,
        repairs=RepairLog(),
        gaps=gaps,
    )


def test_owned_ranges_tile_the_series_once() -> None:
    chunks = chunk_rows(1003, 100, carry_before=37, carry_after=5)
    owned = np.concatenate([np.arange(c.own_start, c.own_stop) for c in chunks])
    np.testing.assert_array_equal(owned, np.arange(1003))
    assert all(c.start == max(0, c.own_start - 37) and c.stop == min(1003, c.own_stop + 5) for c in chunks)


def test_sliding_statistic_on_chunks_with_carry_over_equals_the_whole_series() -> None:
    """A chunk reading the detector's window around what it owns gives the whole-series values."""
    x = np.random.default_rng(3).normal(size=(5000, 3))
    x[2600:] += 0.5  # a step
    cfg = WindowConfig(pre=200, post=180)
    whole = sliding_statistic("glr", x, cfg)[:, 0]
    pieces = np.full(x.shape[0], np.nan)
    for c in chunk_rows(x.shape[0], 700, carry_before=cfg.pre, carry_after=cfg.guard + cfg.post - 1):
        part = sliding_statistic("glr", x[c.start : c.stop], cfg)[:, 0]
        keep = c.owns(np.arange(part.size))
        pieces[np.arange(c.start, c.stop)[keep]] = part[keep]
    ok = np.isfinite(whole)
    np.testing.assert_array_equal(np.isfinite(pieces), ok)
    np.testing.assert_allclose(pieces[ok], whole[ok], rtol=1e-9, atol=1e-12)


def test_telemetry_rows_restart_time_and_clip_segments() -> None:
    tel = _telemetry(300, gap_at=120)
    assert tel.segments == [(0, 120), (120, 300)]
    part = tel.rows(100, 200)
    assert len(part) == 100 and part.t_s[0] == 0.0
    assert part.segments == [(0, 20), (20, 100)]
    assert part.gaps == [(20, pytest.approx(1.1))]
    assert part.time[0] == tel.time[100]
    chunks = list(telemetry_chunks(tel, 10.0, carry_before_s=2.0))
    assert isinstance(chunks[0][0], Chunk) and sum(c.own_stop - c.own_start for c, _ in chunks) == 300
    assert chunks[1][0].carry_before == 20


def test_shifted_moves_every_time_by_the_offset() -> None:
    tel = _telemetry(50)
    moved = tel.shifted(3600.5)
    assert np.all(moved.time - tel.time == np.timedelta64(3600500, "ms"))
    np.testing.assert_array_equal(moved.t_s, tel.t_s)


def test_robust_scale_matches_scipy_normal_mad() -> None:
    x = np.random.default_rng(0).standard_t(4, size=(2000, 2))
    expected = stats.median_abs_deviation(x, axis=0, scale="normal")
    np.testing.assert_allclose(robust_scale(x, axis=0), expected, rtol=2e-6)  # 1.4826 vs 1/Φ⁻¹(3/4)
    assert float(robust_scale(x[:, 0])) == pytest.approx(expected[0], rel=2e-6)


def test_robust_scale_is_the_same_number_with_and_without_nan_in_the_data() -> None:
    # Without NaN the plain median is taken (faster); the result must be numpy's nanmedian one exactly.
    rng = np.random.default_rng(11)
    for n in (3, 8, 599, 600, 1001):
        x = np.round(rng.standard_normal((n, 3)), 2)  # ties, even and odd counts
        x[0, 0] = np.inf
        for axis in (None, 0, 1):
            med = np.nanmedian(x, axis=axis, keepdims=True)
            expected = 1.4826 * np.nanmedian(np.abs(x - med), axis=axis)
            assert np.array_equal(robust_scale(x, axis=axis), expected)
    x[1, 1] = np.nan  # the NaN path: the NaN sample is left out
    assert robust_scale(x, axis=0)[1] == robust_scale(np.delete(x[:, 1], 1))


def test_robust_noise_sigma_is_the_robust_scale_of_differences_over_root_two() -> None:
    x = np.random.default_rng(5).normal(size=(4000, 1)) * 0.2
    assert robust_noise_sigma(x)[0] == pytest.approx(float(robust_scale(np.diff(x[:, 0]))) / np.sqrt(2.0))
    assert robust_noise_sigma(x)[0] == pytest.approx(0.2, rel=0.05)
