"""Attitude thresholds from event-free momentum simulated and reduced chunk by chunk.

The simulated null, its statistic and its block maxima are produced piece by piece so that memory does not
grow with ``null_samples``. The independent truth is the whole-array computation (``simulate`` of every
row, the batch statistic, ``block_maxima``): the pieces must give the same numbers to the bit, and the
threshold the same value, for every statistic and for chunk sizes shorter and longer than a window span.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from abrupt.detect.attitude.momentum import (
    CusumDetector,
    GlrDetector,
    ShiryaevDetector,
    SummationDetector,
    statistic_in_chunks,
)
from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.readers.telemetry import telemetry_from_frame
from abrupt.series.attitude import AttitudeSeries
from abrupt.simulate.attitude import simulate_attitude
from abrupt.thresholds import BlockMaxima, FalseAlarmBudget, block_maxima, fit_block_maxima_threshold
from abrupt.thresholds.noise import NULL_CHUNK_SAMPLES, MomentumNoiseModel

MODEL = MomentumNoiseModel(np.array([0.1, 0.12, 0.08]), np.array([1e-4, 5e-5, 0.0]))


@pytest.mark.parametrize("chunk", [1, 997, 4096, 30_001, 100_000])
def test_simulated_chunks_are_the_whole_simulation_to_the_bit(chunk: int) -> None:
    whole = MODEL.simulate(30_001, seed=5)
    pieces = list(MODEL.simulate_chunks(30_001, seed=5, chunk_samples=chunk))
    assert max(p.shape[0] for p in pieces) <= chunk
    assert np.array_equal(np.concatenate(pieces), whole)
    # a prefix of the rows is the prefix of the same simulation (the walk's draws follow all white draws)
    assert np.array_equal(
        np.concatenate(list(MODEL.simulate_chunks(30_001, 5, rows=2_500, chunk_samples=999))), whole[:2_500]
    )


@pytest.mark.parametrize("detector", [GlrDetector(), CusumDetector(), SummationDetector(), ShiryaevDetector()])
@pytest.mark.parametrize("chunk_spans", [0.4, 2.1, 5.0])
def test_the_statistic_of_chunks_is_the_statistic_of_the_whole(detector: GlrDetector, chunk_spans: float) -> None:
    """Chunks shorter than a window span, a little longer and much longer; the last one partial."""
    span = detector.windows.span
    n, chunk = 8 * span + 17, round(chunk_spans * span)
    whole = detector.combined_statistic(MODEL.simulate(n, seed=2))
    pieces = statistic_in_chunks(
        detector.combined_statistic, MODEL.simulate_chunks(n, 2, chunk_samples=chunk), detector.windows
    )
    joined = np.concatenate(list(pieces))
    assert joined.shape == whole.shape
    assert np.array_equal(joined, whole, equal_nan=True)
    assert np.isfinite(whole).sum() == n - span + 1  # the comparison covers every junction


def test_block_maxima_pushed_piece_by_piece_are_those_of_the_whole() -> None:
    rng = np.random.default_rng(0)
    x = rng.normal(size=10_007)
    x[:700] = np.nan  # a first block with no finite value is skipped, as in the whole
    stream = BlockMaxima(500)
    for cut in np.array_split(x, [3, 499, 500, 4_321, 9_999]):
        stream.push(cut)
    assert np.array_equal(stream.maxima, block_maxima(x, 500))
    assert stream.maxima.size == 10_007 // 500 - 1


@pytest.fixture(scope="module")
def quiet_series() -> AttitudeSeries:
    sc = load_spacecraft(bundled_spacecraft_path())
    sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=900.0, seed=3), [])
    return AttitudeSeries(telemetry_from_frame(sim.telemetry, sc), sc)


def test_the_streamed_threshold_equals_the_whole_array_threshold(quiet_series: AttitudeSeries) -> None:
    """More simulated samples than one chunk holds, so the threshold is made of several pieces."""
    n = 2 * NULL_CHUNK_SAMPLES + 12_345
    detector = GlrDetector(null_samples=n, seed=7)
    budget = FalseAlarmBudget(1.0, "day")
    dt = quiet_series.telemetry.sample_interval_s
    calibration = detector.calibrate(quiet_series, budget)
    whole = quiet_series.noise_model.simulate(n, 7)
    expected = fit_block_maxima_threshold(
        detector.statistic(whole, [(0, n)]), sample_rate_hz=1.0 / dt, budget=budget, block_s=detector.block_s(dt)
    )
    assert calibration.threshold == expected
    assert calibration.null_sample is not None and calibration.null_sample.size == expected.n_samples // round(
        detector.block_s(dt) / dt
    )


def test_calibration_memory_does_not_grow_with_the_simulated_samples(quiet_series: AttitudeSeries) -> None:
    """Peak traced allocation of a calibration at 2.5 and 8 chunks of samples: the same, not 3.2 times."""
    budget = FalseAlarmBudget(1.0, "day")
    peaks = []
    assert quiet_series.noise_model is not None  # measured once, before tracing
    for n in (int(2.5 * NULL_CHUNK_SAMPLES), 8 * NULL_CHUNK_SAMPLES):
        tracemalloc.start()
        GlrDetector(null_samples=n).calibrate(quiet_series, budget)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    assert peaks[1] < 1.15 * peaks[0]
    assert peaks[1] < 8 * NULL_CHUNK_SAMPLES * 3 * 8  # less than the larger null's rows alone, held whole
