"""Matched filters on attitude and rate telemetry (Bennett 2022 §2.2, §2.4.1).

Synthetic tests use a known wavelet in white Gaussian noise, where the filter output has an analytic
distribution (mean = strike size at the strike sample, sd = sigma dH / ||s||). Simulator tests
(skipped until ``abrupt.simulate.attitude`` imports) check the wavelets built from the dynamics.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from abrupt.detect.attitude.matched_filter import (
    CombinedFilter,
    CombinedFilterStream,
    MatchedFilterStream,
    WaveletSet,
    analytic_output_sd,
    attitude_error_vector,
    build_wavelets,
    detect_matched_filter,
    detect_strikes,
    detections_to_events,
    estimate_strike_size,
    fit_matched_filter_thresholds,
    largest_unsaturated_strike_Nms,
    matched_filter_bank_statistics,
    matched_filter_statistic,
)
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike, simulate_attitude_batch
from abrupt.model.rotations import quaternion_from_mrp, quaternion_multiply
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.thresholds import FalseAlarmBudget

RATE_HZ = 10.0
LENGTH = 250


def _response(dh: float, axis: int) -> np.ndarray:
    """A damped second-order rate response (L, 3) to a strike dh about ``axis``, with small coupling."""
    t = np.arange(LENGTH) / RATE_HZ
    j = np.array([3000.0, 2500.0, 3500.0])[axis]
    on = dh / j * np.exp(-0.18 * t) * np.cos(0.09 * t)
    out = np.zeros((LENGTH, 3))
    out[:, axis] = on
    out[:, (axis + 1) % 3] = 0.02 * on * np.sin(0.3 * t)
    return out


def _synthetic_wavelets() -> WaveletSet:
    sizes = np.array([0.64, 0.6, 0.7])
    ladder = np.linspace(0.0, 0.6, 13)
    rate = np.stack([_response(sizes[a], a) for a in range(3)])
    bank = np.stack([np.stack([_response(d, a) for a in range(3)]) for d in ladder])
    return WaveletSet(
        sample_rate_hz=RATE_HZ,
        dH_Nms=sizes,
        attitude=rate * 10.0,
        rate=rate,
        bank_dH_Nms=ladder,
        bank_attitude=bank * 10.0,
        bank_rate=bank,
        spacecraft="synthetic",
    )


def _naive_filter(x: np.ndarray, s: np.ndarray, dh: float, nb: int) -> np.ndarray:
    out = np.full(x.size, np.nan)
    for n in range(nb, x.size - s.size + 1):
        base = x[n - nb : n].mean() if nb else 0.0
        out[n] = np.dot(s, x[n : n + s.size] - base) / np.dot(s, s) * dh
    return out


@pytest.mark.parametrize("baseline", [0, 30])
@pytest.mark.parametrize("length", [20, 250])
def test_filter_equals_direct_correlation_sum(baseline: int, length: int) -> None:
    rng = np.random.default_rng(1)
    x = rng.normal(size=900) + 0.3
    s = rng.normal(size=length)
    got = matched_filter_statistic(x, s, dH_wavelet_Nms=0.5, baseline_samples=baseline)
    np.testing.assert_allclose(got, _naive_filter(x, s, 0.5, baseline), rtol=1e-9, atol=1e-12, equal_nan=True)


@pytest.mark.parametrize("baseline", [0, 40])
def test_streaming_matches_batch_for_any_chunking(baseline: int) -> None:
    rng = np.random.default_rng(2)
    x = rng.normal(size=3000)
    x[1500:1503] = np.nan
    s = np.exp(-np.arange(250) / 30.0)
    batch = matched_filter_statistic(x, s, dH_wavelet_Nms=0.64, baseline_samples=baseline)
    for chunks in ([1] * 400 + [2600], [7, 300, 1, 999, 1693], [3000]):
        stream = MatchedFilterStream(s, dH_wavelet_Nms=0.64, baseline_samples=baseline)
        parts, i = [], 0
        for c in chunks:
            parts.append(stream.update(x[i : i + c]))
            i += c
        parts.append(stream.flush())
        got = np.concatenate(parts)
        assert got.size == x.size
        np.testing.assert_allclose(got, batch, rtol=1e-9, atol=1e-12, equal_nan=True)


def test_streaming_memory_is_bounded() -> None:
    s = np.ones(250)
    stream = MatchedFilterStream(s, baseline_samples=100)
    for _ in range(50):
        stream.update(np.zeros(10_000))
    assert stream._tail.size <= 100 + 250 - 1


def test_noise_only_output_has_analytic_sd_and_is_gaussian() -> None:
    rng = np.random.default_rng(3)
    sigma = 2e-4
    wav = _synthetic_wavelets()
    s = wav.wavelet("rate", 0)
    x = rng.normal(scale=sigma, size=200_000)
    y = matched_filter_statistic(x, s, dH_wavelet_Nms=0.64)
    y = y[np.isfinite(y)]
    expected = analytic_output_sd(s, sigma, dH_wavelet_Nms=0.64)
    # Independent truth: sd = sigma * dH / ||s|| for white noise.
    assert np.std(y) == pytest.approx(expected, rel=0.05)
    assert abs(stats.skew(y[::250])) < 0.15


def test_noise_free_strike_peaks_at_its_sample_with_its_size() -> None:
    wav = _synthetic_wavelets()
    x = np.zeros((2000, 3))
    x[700 : 700 + LENGTH] += _response(0.3, 1)
    stat = matched_filter_bank_statistics("rate", x, wav)
    assert int(np.nanargmax(np.abs(stat[:, 1]))) == 700
    assert stat[700, 1] == pytest.approx(0.3, rel=1e-9)


def test_gap_makes_touching_outputs_nan_only() -> None:
    x = np.zeros(1000)
    x[500] = np.nan
    y = matched_filter_statistic(x, np.ones(100))
    assert np.all(np.isnan(y[401:501]))
    assert np.all(np.isfinite(y[:401]))
    assert np.all(np.isfinite(y[501:901]))


def test_gaussian_thresholds_match_analytic_quantile() -> None:
    rng = np.random.default_rng(4)
    sigma = 4e-5
    wav = _synthetic_wavelets()
    null = matched_filter_bank_statistics("rate", rng.normal(scale=sigma, size=(100_000, 3)), wav)
    thr = fit_matched_filter_thresholds(null, p_fa=1e-4, sample_rate_hz=RATE_HZ)
    z = stats.norm.isf(0.5e-4)
    for a in range(3):
        sd = analytic_output_sd(wav.wavelet("rate", a), sigma, dH_wavelet_Nms=float(wav.dH_Nms[a]))
        assert thr[a].value == pytest.approx(z * sd, rel=0.05)
        assert thr[a].p_fa == 1e-4


def test_detection_rate_matches_gaussian_power() -> None:
    """P_D of a strike of size d at threshold c, output sd s: Phi((d - c)/s) (independent truth)."""
    rng = np.random.default_rng(5)
    sigma = 2e-4
    wav = _synthetic_wavelets()
    sd = analytic_output_sd(wav.wavelet("rate", 0), sigma, dH_wavelet_Nms=0.64)
    c = stats.norm.isf(0.5e-4) * sd
    d = c + 0.5 * sd  # expected P_D about Phi(0.5) = 0.69 at the exact sample
    runs, hits = 300, 0
    for _ in range(runs):
        x = rng.normal(scale=sigma, size=(LENGTH + 1, 3))
        x[:LENGTH] += _response(d, 0)
        st = matched_filter_bank_statistics("rate", x, wav)
        hits += abs(st[0, 0]) > c
    expected = stats.norm.cdf(0.5)
    assert hits / runs == pytest.approx(expected, abs=3 * math.sqrt(expected * (1 - expected) / runs))


@pytest.mark.parametrize("metric", ["mmse", "rsse", "mae", "cubic"])
def test_bank_recovers_size_on_every_axis(metric: str) -> None:
    wav = _synthetic_wavelets()
    seg = _response(0.25, 0) - _response(0.45, 2) + _response(0.0, 1)
    est = estimate_strike_size("rate", seg, wav, metric=metric)  # type: ignore[arg-type]
    np.testing.assert_allclose(est, [0.25, 0.0, -0.45], atol=1e-12)


def test_bank_mmse_and_rsse_rank_identically_in_noise() -> None:
    rng = np.random.default_rng(6)
    wav = _synthetic_wavelets()
    for _ in range(20):
        seg = _response(0.3, 1) + rng.normal(scale=1e-4, size=(LENGTH, 3))
        a = estimate_strike_size("rate", seg, wav, metric="mmse")
        b = estimate_strike_size("rate", seg, wav, metric="rsse")
        np.testing.assert_array_equal(a, b)


def test_attitude_error_vector_is_half_angle_about_body_axis() -> None:
    phi = 1e-3
    ref = quaternion_from_mrp(np.array([0.1, -0.2, 0.05]))
    # q_BN = q_BR ⊗ q_RN with q_BR a small rotation about body y.

    q_br = np.array([math.cos(phi / 2), 0.0, math.sin(phi / 2), 0.0])
    q = quaternion_multiply(q_br, ref)[None, :]
    err = attitude_error_vector(np.vstack([ref[None, :], q]))
    np.testing.assert_allclose(err[1], [0.0, math.sin(phi / 2), 0.0], atol=1e-15)
    np.testing.assert_allclose(err[0], 0.0, atol=1e-15)


def test_detect_returns_one_row_per_strike_with_time_and_inertial_dh() -> None:
    rng = np.random.default_rng(7)
    wav = _synthetic_wavelets()
    sigma = 4e-5
    n = 6000
    t = np.datetime64("2024-01-01T00:00:00", "ns") + (np.arange(n) * 100_000_000).astype("timedelta64[ns]")
    w = rng.normal(scale=sigma, size=(n, 3))
    w[1000 : 1000 + LENGTH] += _response(0.4, 0)
    w[4000 : 4000 + LENGTH] -= _response(0.5, 2)
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    null = matched_filter_bank_statistics("rate", rng.normal(scale=sigma, size=(50_000, 3)), wav)
    thr = fit_matched_filter_thresholds(null, budget=FalseAlarmBudget(1.0), sample_rate_hz=RATE_HZ)
    det = detect_matched_filter("rate", t, q, w, wav, thr, reference_q_BN=q[0])
    assert list(det["index"]) == pytest.approx([1000, 4000], abs=1)
    assert list(det["axis"]) == [0, 2]
    assert det["dH_N_x_Nms"].iloc[0] == pytest.approx(0.4, abs=0.06)
    assert det["dH_N_z_Nms"].iloc[1] == pytest.approx(-0.5, abs=0.06)
    assert det["false_alarms_per_day"].iloc[0] == pytest.approx(1.0)
    events = detections_to_events(det, spacecraft="sc", run_id="r", config_hash="h", sample_rate_hz=RATE_HZ)
    assert events[0].time_utc.startswith(str(pd.Timestamp(t[int(det["index"].iloc[0])]).date()))
    assert events[1].dH_Nms == pytest.approx(det["dH_Nms"].iloc[1])


def test_detect_finds_nothing_in_noise_and_keeps_columns() -> None:
    rng = np.random.default_rng(8)
    wav = _synthetic_wavelets()
    n = 5000
    w = rng.normal(scale=4e-5, size=(n, 3))
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    null = matched_filter_bank_statistics("rate", rng.normal(scale=4e-5, size=(50_000, 3)), wav)
    thr = fit_matched_filter_thresholds(null, budget=FalseAlarmBudget(1.0), sample_rate_hz=RATE_HZ)
    det = detect_matched_filter("rate", np.arange(n) / RATE_HZ, q, w, wav, thr)
    assert det.empty and "dH_N_x_Nms" in det.columns


def test_detect_rejects_mismatched_shapes() -> None:
    wav = _synthetic_wavelets()
    with pytest.raises(ValueError, match="q_BN"):
        detect_matched_filter("rate", np.arange(10.0), np.zeros((9, 4)), np.zeros((10, 3)), wav, [])


def test_wavelet_set_round_trips_through_npz(tmp_path) -> None:  # type: ignore[no-untyped-def]
    wav = _synthetic_wavelets()
    path = str(tmp_path / "w.npz")
    wav.save(path)
    back = WaveletSet.load(path)
    np.testing.assert_array_equal(back.bank_rate, wav.bank_rate)
    assert back.sample_rate_hz == RATE_HZ and back.spacecraft == "synthetic"


def test_largest_unsaturated_strike_matches_thesis_estimate() -> None:
    """Spec §2.1: with P = 1080 N·m·s the largest unsaturated x strike is about 80-90 mg (0.64-0.72)."""

    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    dh = largest_unsaturated_strike_Nms(sc, 0)
    assert 0.62 < dh < 0.74


def test_combined_stream_matches_batch() -> None:

    rng = np.random.default_rng(9)
    wav = _synthetic_wavelets()
    filt = CombinedFilter.from_wavelets(wav, [7e-4] * 3 + [4e-5] * 3)
    x = rng.normal(size=(1500, 6)) * filt.noise_sd
    x[600 : 600 + LENGTH, 3:] += _response(0.3, 1)
    t_batch, dh_batch = filt.statistic(x, baseline_samples=20)
    stream = CombinedFilterStream(filt, baseline_samples=20)
    outs = [stream.update(x[i : i + 97]) for i in range(0, 1500, 97)] + [stream.flush()]
    t_stream = np.concatenate([o[0] for o in outs])
    dh_stream = np.concatenate([o[1] for o in outs])
    np.testing.assert_allclose(t_stream, t_batch, rtol=1e-8, equal_nan=True)
    np.testing.assert_allclose(dh_stream, dh_batch, rtol=1e-8, atol=1e-12, equal_nan=True)


def test_combined_statistic_is_chi2_3_in_white_noise() -> None:

    rng = np.random.default_rng(10)
    wav = _synthetic_wavelets()
    sd = np.array([7e-4] * 3 + [4e-5] * 3)
    filt = CombinedFilter.from_wavelets(wav, sd)
    x = rng.normal(size=(100_000, 6)) * sd + 1e-3  # a constant offset, removed by the baseline
    for baseline in (0, 300):
        t_stat, _ = filt.statistic(x - (1e-3 if baseline == 0 else 0.0), baseline_samples=baseline)
        t_stat = t_stat[np.isfinite(t_stat)]
        assert np.mean(t_stat) == pytest.approx(3.0, rel=0.05)  # chi-square(3) mean
        assert np.mean(t_stat > stats.chi2.isf(0.01, 3)) == pytest.approx(0.01, rel=0.3)


# ---------------------------------------------------------------------------------------------
# With the attitude simulator (Bennett 2022 §2.1)
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def thesis_wavelets():  # type: ignore[no-untyped-def]
    pytest.importorskip("abrupt.simulate.attitude")

    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    return sc, build_wavelets(sc, bank_size=16)


def test_simulated_rate_wavelet_starts_at_dh_over_inertia_and_decays(thesis_wavelets) -> None:  # type: ignore[no-untyped-def]
    sc, wav = thesis_wavelets
    inertia = np.diag(sc.inertia_kgm2)
    for a in range(3):
        s = wav.wavelet("rate", a)
        # Conservation of angular momentum across the impulse: omega jumps by J^-1 dH (wheels not yet
        # moved). The first sample is the pre-strike state; samples 1 and 2 (0.1 s and 0.2 s after the
        # strike) are extrapolated back to the strike with the local exponential decay.
        assert s[0] == 0.0
        assert s[1] ** 2 / s[2] == pytest.approx(wav.dH_Nms[a] / inertia[a], rel=0.01)
        assert abs(s[-1]) < 0.05 * np.max(np.abs(s))  # response over within the 25 s wavelet
        off = np.delete(wav.rate[a], a, axis=1)
        assert np.max(np.abs(off)) < 1e-3 * np.max(np.abs(s))  # weak gyroscopic cross-coupling


def test_simulated_bank_is_linear_below_saturation(thesis_wavelets) -> None:  # type: ignore[no-untyped-def]
    _, wav = thesis_wavelets
    m = 3  # a small ladder member, far from saturation
    scaled = wav.bank_rate[m, 0] / wav.bank_dH_Nms[m] * wav.dH_Nms[0]
    np.testing.assert_allclose(scaled, wav.rate[0], atol=1e-6 * np.max(np.abs(wav.rate[0])))


def test_simulated_strike_is_detected_with_time_and_size(thesis_wavelets) -> None:  # type: ignore[no-untyped-def]

    sc, wav = thesis_wavelets
    cfg = AttitudeSimConfig(duration_s=600.0, telemetry_rate_hz=10.0)
    dh_b = np.array([0.3, -0.25, 0.2])  # about 54 mg
    out = simulate_attitude_batch(sc, cfg, [[], [Strike(300.05, tuple(dh_b))]], [1, 2])  # type: ignore[arg-type]
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    null = matched_filter_bank_statistics("attitude", attitude_error_vector(out["q_BN"][0], q0), wav)
    thr = fit_matched_filter_thresholds(null, budget=FalseAlarmBudget(1.0), sample_rate_hz=10.0)
    det = detect_matched_filter(
        "attitude", out["t_s"], out["q_BN"][1], out["omega_B_rad_s"][1], wav, thr, reference_q_BN=q0
    )
    assert len(det) == 1
    # The attitude wavelet is smooth, so its peak times a strike to a few tenths of a second; the
    # reported Cramer-Rao sigma must cover the error.
    sigma = det["time_sigma_s"].iloc[0]
    assert 0.05 < sigma < 1.0
    assert det["time"].iloc[0] == pytest.approx(300.0, abs=max(4 * sigma, 0.2))
    est = det[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy()[0]
    np.testing.assert_allclose(est, out["strike_dH_N_Nms"][1, 0], atol=0.06)


@pytest.mark.slow
def test_thesis_attitude_filter_detects_60mg_random_directions(thesis_wavelets) -> None:  # type: ignore[no-untyped-def]
    """Acceptance 2 (Bennett 2022 §2.4.1.4): >= 90% of 60 mg strikes at alpha = 1e-4."""

    sc, wav = thesis_wavelets
    rng = np.random.default_rng(11)
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    null_out = simulate_attitude_batch(sc, AttitudeSimConfig(duration_s=1800.0), [[]], [5])
    null = matched_filter_bank_statistics("attitude", attitude_error_vector(null_out["q_BN"][0], q0), wav)
    thr = np.array([t.value for t in fit_matched_filter_thresholds(null, p_fa=1e-4)])
    runs = 200
    dirs = rng.normal(size=(runs, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    strikes = [[Strike(10.0, tuple(0.48 * d))] for d in dirs]  # type: ignore[arg-type]
    out = simulate_attitude_batch(sc, AttitudeSimConfig(duration_s=40.0), strikes, list(range(100, 100 + runs)))
    hits = 0
    for r in range(runs):
        st = matched_filter_bank_statistics("attitude", attitude_error_vector(out["q_BN"][r], q0), wav)
        hits += bool(np.nanmax(np.abs(st[90:111]) / thr) > 1.0)
    assert hits / runs >= 0.9


def test_detect_strikes_sets_thresholds_from_the_series_and_finds_the_strike() -> None:

    rng = np.random.default_rng(12)
    wav = _synthetic_wavelets()
    n = 20_000
    w = rng.normal(scale=4e-5, size=(n, 3))
    w[9000 : 9000 + LENGTH] += _response(0.35, 1)
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    q[:, 1:] += rng.normal(scale=7e-5, size=(n, 3))
    q[9000 : 9000 + LENGTH, 1:] += 10.0 * _response(0.35, 1)  # the synthetic attitude wavelet is 10x rate
    det, used = detect_strikes(np.arange(n) / RATE_HZ, q, w, wav, kinds=("rate", "combined"))
    assert set(det["detector"]) == {"mf_rate", "mf_combined"}
    assert np.all(np.abs(det["index"] - 9000) <= 1)
    # Robust threshold agrees with the white-noise analytic one (z * sd) within a few percent.
    sd = analytic_output_sd(wav.wavelet("rate", 1), 4e-5, dH_wavelet_Nms=float(wav.dH_Nms[1]))
    z = stats.norm.isf(1.0 / 3.0 / 864_000 / 2.0)
    assert used["rate"][1].value == pytest.approx(z * sd, rel=0.05)
    assert used["rate"][1].false_alarms_per_day == pytest.approx(1.0 / 3.0)


def test_detect_strikes_rejects_wrong_sample_rate() -> None:

    wav = _synthetic_wavelets()
    n = 1000
    with pytest.raises(ValueError, match="does not match"):
        detect_strikes(np.arange(n) / 5.0, np.tile([1.0, 0, 0, 0], (n, 1)), np.zeros((n, 3)), wav)


def test_long_series_blocked_fft_equals_direct_correlation() -> None:
    rng = np.random.default_rng(13)
    x = rng.normal(size=150_000)
    s = rng.normal(size=250)
    got = matched_filter_statistic(x, s, dH_wavelet_Nms=float(np.dot(s, s)))
    direct = np.correlate(x, s, mode="valid")
    np.testing.assert_allclose(got[: direct.size], direct, rtol=1e-9, atol=1e-9)
    assert np.all(np.isnan(got[direct.size :]))


def test_simulated_strike_momentum_ends_in_the_wheels(thesis_wavelets) -> None:  # type: ignore[no-untyped-def]
    """Conservation: after the response J omega + Js G dOmega equals the applied dH (Bennett 2022 Eq. 2.6)."""
    sc, wav = thesis_wavelets
    g = sc.wheel_axes
    js = sc.wheel_spin_inertias_kgm2
    for a in range(3):
        h_end = sc.inertia_kgm2 @ wav.rate[a, -1] + g @ (js * wav.wheel[a, -1])
        np.testing.assert_allclose(h_end, wav.dH_Nms[a] * np.eye(3)[a], atol=1e-6 * wav.dH_Nms[a])


def test_joint_filter_with_wheels_detects_a_5mg_strike(thesis_wavelets) -> None:  # type: ignore[no-untyped-def]

    sc, wav = thesis_wavelets
    dh_b = 0.04 * np.array([0.6, -0.64, 0.48])  # 5 mg, |dH| = 0.04 N·m·s
    out = simulate_attitude_batch(sc, AttitudeSimConfig(duration_s=900.0), [[Strike(450.0, tuple(dh_b))]], [3])  # type: ignore[arg-type]
    det, used = detect_strikes(
        out["t_s"],
        out["q_BN"][0],
        out["omega_B_rad_s"][0],
        wav,
        kinds=("joint", "combined"),
        wheel_speed_rad_s=out["wheel_speed_rad_s"][0],
        baseline_samples=200,
    )
    joint = det[det["detector"] == "mf_joint"]
    assert len(joint) == 1  # and no false alarm in 15 min
    sigma = joint["time_sigma_s"].iloc[0]
    assert joint["time"].iloc[0] == pytest.approx(450.0, abs=max(4.0 * sigma, 0.3))
    est = joint[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy()[0]
    np.testing.assert_allclose(est, out["strike_dH_N_Nms"][0, 0], atol=0.015)
    assert (det["detector"] == "mf_combined").sum() == 0  # the attitude+rate filter cannot see 5 mg
    assert used["joint"].false_alarms_per_day == pytest.approx(1.0)


def test_attitude_error_ignores_quaternion_scale_and_sign() -> None:
    rng = np.random.default_rng(14)
    q = quaternion_from_mrp(rng.normal(scale=1e-3, size=(50, 3)))
    scaled = q * rng.uniform(0.5, 2.0, size=(50, 1)) * np.where(rng.random((50, 1)) < 0.5, -1.0, 1.0)
    np.testing.assert_allclose(attitude_error_vector(scaled, q[0]), attitude_error_vector(q, q[0]), atol=1e-15)


def test_empty_or_too_short_telemetry_gives_a_clear_error() -> None:

    wav = _synthetic_wavelets()
    with pytest.raises(ValueError, match="at least 10 finite"):
        detect_strikes(np.zeros(0), np.zeros((0, 4)), np.zeros((0, 3)), wav, kinds=("rate",))
