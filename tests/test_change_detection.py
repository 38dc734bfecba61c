"""Change detectors on momentum: direct formulas, analytic null moments, streaming equals batch."""

from __future__ import annotations

import numpy as np
import pytest

from abrupt.detect.attitude.change_detection import (
    STATISTICS,
    StreamingStatistic,
    WindowConfig,
    sliding_statistic,
)
from abrupt.detect.attitude.steps import mean_difference_step, peaks

CFG = WindowConfig(pre=50, post=40, cusum_delta_mu_Nms=0.1)
RNG = np.random.default_rng(7)
X = RNG.normal(0.0, 0.13, size=(3000, 3))
X[1500:, 0] += 0.2


def _pre_post(x: np.ndarray, n: int, cfg: WindowConfig) -> tuple[np.ndarray, np.ndarray]:
    return x[n - cfg.pre : n], x[n + cfg.guard : n + cfg.guard + cfg.post]


def test_summation_is_the_post_window_sum_minus_the_pre_mean() -> None:
    out = sliding_statistic("summation", X, CFG)
    for n in (50, 777, 1500, 2910):
        pre, post = _pre_post(X, n, CFG)
        np.testing.assert_allclose(out[n], (post - pre.mean(axis=0)).sum(axis=0), rtol=1e-9, atol=1e-12)
    assert np.all(np.isnan(out[:50])) and np.all(np.isnan(out[-CFG.post + 1 :]))


def test_cusum_matches_a_plain_loop_over_the_log_likelihood_ratio() -> None:
    out = sliding_statistic("cusum", X, CFG)
    for n in (60, 1490, 1500, 2500):
        pre, post = _pre_post(X[:, 0], n, CFG)
        mu, sd = pre.mean(), pre.std(ddof=1)
        a, h = CFG.cusum_delta_mu_Nms / sd**2, CFG.cusum_delta_mu_Nms / 2
        gp = gn = 0.0
        for v in post:
            gp = max(0.0, gp + a * (v - mu - h))
            gn = max(0.0, gn + a * (-(v - mu) - h))
        assert out[n, 0] == pytest.approx(max(gp, gn), rel=1e-5, abs=1e-5)


def test_glr_is_the_mahalanobis_distance_of_the_mean_difference() -> None:
    out = sliding_statistic("glr", X, CFG)
    n = 1500
    pre, post = _pre_post(X, n, CFG)
    d = post.mean(axis=0) - pre.mean(axis=0)
    cov = np.cov(pre.T) * (1 / CFG.pre + 1 / CFG.post)
    assert out[n, 0] == pytest.approx(np.sqrt(d @ np.linalg.solve(cov, d)), rel=1e-9)


def test_mean_difference_estimates_the_step() -> None:
    out = sliding_statistic("mean_difference", X, CFG)
    assert out[1500, 0] == pytest.approx(0.2, abs=4 * 0.13 * np.sqrt(1 / 50 + 1 / 40))
    assert abs(out[1500, 1]) < 4 * 0.13 * np.sqrt(1 / 50 + 1 / 40)


def test_shiryaev_estimates_the_step_size_on_its_hypothesis_grid() -> None:
    x = np.zeros((500, 1)) + RNG.normal(0, 0.01, size=(500, 1))
    x[250:] += 0.12
    out = sliding_statistic("shiryaev", x, WindowConfig(pre=100, post=100))
    assert out[250, 0] == pytest.approx(0.12, abs=0.02)
    # plateau: any post-window that contains the step reports it; one that does not reports ~0
    assert out[200, 0] == pytest.approx(0.12, abs=0.02)
    assert abs(out[120, 0]) < 0.02


def test_summation_null_standard_deviation_matches_the_analytic_value() -> None:
    # Var(sum_post (x - mean_pre)) = sigma^2 (post + post^2 / pre) for white noise (spec §3.6).
    x = np.random.default_rng(3).normal(0.0, 0.129, size=(400_000, 1))
    cfg = WindowConfig()
    s = sliding_statistic("summation", x, cfg)
    sd = np.nanstd(s)
    assert sd == pytest.approx(0.129 * np.sqrt(180 + 180**2 / 200), rel=0.05)


def test_a_step_peaks_at_the_junction() -> None:
    for name in ("summation", "glr", "mean_difference"):
        out = np.abs(sliding_statistic(name, X[:, :1] if name != "glr" else X, CFG)[:, 0])
        assert abs(int(np.nanargmax(out)) - 1500) <= 5


@pytest.mark.parametrize("name", STATISTICS)
def test_streaming_gives_exactly_the_batch_values(name: str) -> None:
    cfg = WindowConfig(pre=50, post=40, guard=7)
    batch = sliding_statistic(name, X, cfg)
    stream = StreamingStatistic(name, channels=3, config=cfg)
    rng = np.random.default_rng(0)
    got_idx, got_val, pos = [], [], 0
    while pos < X.shape[0]:
        size = int(rng.integers(1, 700))
        idx, val = stream.push(X[pos : pos + size])
        got_idx.append(idx)
        got_val.append(val)
        pos += size
    idx = np.concatenate(got_idx)
    val = np.concatenate(got_val)
    assert idx.size == X.shape[0] - cfg.span + 1
    np.testing.assert_array_equal(batch[idx], val)


def test_streaming_one_sample_at_a_time_has_bounded_memory() -> None:
    stream = StreamingStatistic("cusum", channels=1, config=CFG)
    sizes = []
    for v in X[:2500, 0]:
        stream.push(np.array([v]))
        sizes.append(stream._buffer.shape[0])
    assert max(sizes) <= CFG.span + 1024
    assert stream.samples_seen == 2500


def test_bad_window_settings_are_rejected() -> None:
    with pytest.raises(ValueError):
        WindowConfig(pre=1)
    with pytest.raises(ValueError, match="unknown statistic"):
        sliding_statistic("median", X, CFG)


def test_glr_rejects_more_than_three_channels() -> None:
    with pytest.raises(ValueError, match="1 to 3 channels"):
        sliding_statistic("glr", np.zeros((500, 4)), CFG)


def test_cusum_does_not_lose_precision_on_a_large_offset() -> None:
    base = sliding_statistic("cusum", X[:, :1], CFG)
    shifted = sliding_statistic("cusum", X[:, :1] + 50.0, CFG)  # |H| of a biased-wheel spacecraft
    np.testing.assert_allclose(shifted, base, atol=1e-4)


def test_peaks_are_the_largest_sample_of_each_run_above_the_threshold() -> None:
    stat = np.array([0.0, 2.0, 3.0, 2.0, 0.0, 0.0, 5.0, np.nan, 4.0, 0.0, 0.0, 0.0, 0.0, 2.5])
    # Runs closer than 2 samples join: (1..3), (6..8) joined across the NaN, then 13 alone.
    assert peaks(stat, 1.0, 2) == [(1, 4, 2), (6, 9, 6), (13, 14, 13)]
    # The same groups as splitting the above-threshold indices where they are more than `merge` apart.
    above = np.flatnonzero(np.nan_to_num(stat, nan=-np.inf) > 1.0)
    groups = np.split(above, np.flatnonzero(np.diff(above) > 2) + 1)
    assert [p for _, _, p in peaks(stat, 1.0, 2)] == [int(g[np.argmax(stat[g])]) for g in groups]


def test_peaks_with_a_separation_keep_the_largest_maximum_within_it() -> None:
    stat = np.array([0.0, 5.0, 4.0, 0.0, 0.0, 0.0, 3.0, 0.0, 6.0, np.nan])
    assert [p for _, _, p in peaks(stat, 1.0, 2, separation=2)] == [1, 8]
    assert [p for _, _, p in peaks(stat, 1.0, 1, separation=1)] == [1, 6, 8]


def _suppression_over_the_whole_series(stat: np.ndarray, floor: float, sep: int) -> list[int]:
    """Reference: visit samples above the floor from the largest (earlier first on ties) and keep each one
    no kept sample lies within ``sep`` of."""
    cand = [i for i in range(stat.size) if np.isfinite(stat[i]) and stat[i] > floor]
    kept: list[int] = []
    for i in sorted(cand, key=lambda j: (-stat[j], j)):
        if all(abs(i - k) > sep for k in kept):
            kept.append(i)
    return sorted(kept)


def test_peaks_with_merge_equal_to_the_separation_are_suppression_over_the_whole_series() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        stat = np.round(rng.normal(size=int(rng.integers(1, 80))), 1)  # rounding makes ties
        stat[rng.random(stat.size) < 0.05] = np.nan
        sep = int(rng.integers(1, 8))
        got = [p for _, _, p in peaks(stat, 0.3, sep, separation=sep)]
        assert got == _suppression_over_the_whole_series(stat, 0.3, sep)


def test_mean_difference_step_finds_the_step_sample_whatever_the_cumulative_sum_origin() -> None:
    rng = np.random.default_rng(4)
    h = 0.01 * rng.standard_normal((400, 3))
    h[230:] += np.array([0.2, -0.1, 0.05])
    sigma = np.full(3, 0.01)
    assert mean_difference_step(h, 0, 400, 50, 350, 30, sigma) == 230
    assert mean_difference_step(h, 150, 300, 180, 270, 30, sigma) == 230
