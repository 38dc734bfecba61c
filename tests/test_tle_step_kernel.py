"""The compiled step test and the fast TLE checksum against their plain definitions.

The compiled kernel (abrupt.detect.tle.step_kernels) must give the same numbers, bit for bit, as the
plain-numpy step test it replaces (``StepModel.gap_numpy``: numpy medians of Theil-Sen slopes and of
detrended levels), at every gap, with and without change points cutting the windows, with short
sides allowed, and with a NaN in a series. The checksum must equal the column-by-column definition
(digits count their value, '-' counts 1, modulo 10) and a published element set's check digit.
"""

from __future__ import annotations

import random

import numpy as np
import pytest

from abrupt.detect.tle.config import TleDetectorConfig
from abrupt.detect.tle.noise import drift_noise_rate, robust_scale_rolling, rolling_rate
from abrupt.detect.tle.steps import StepModel, empty_steps, fill_gap, fill_gaps, segment_bounds, segment_bounds_all
from abrupt.readers.omm import read_element_histories
from abrupt.readers.tle import tle_checksum
from abrupt.simulate.tle_catalogue import write_catalogue


@pytest.fixture(scope="module")
def histories(tmp_path_factory: pytest.TempPathFactory) -> list:
    folder = tmp_path_factory.mktemp("catalogue")
    paths = write_catalogue(folder, 6, objects_per_file=6, years=0.5, seed=3)
    return read_element_histories(paths[0])


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True))


def _reference(model: StepModel, gaps: np.ndarray, cps: list[int]) -> tuple[np.ndarray, np.ndarray]:
    values, factors = [], []
    for g in gaps:
        lo, hi = segment_bounds(int(g), cps, model.n)
        steps, factor = model.gap_numpy(int(g), lo, hi)
        values.append([steps[k] for k in model.NAMES])
        factors.append(factor)
    return np.array(values), np.array(factors)


@pytest.mark.parametrize("min_side", [3, 1])
def test_kernel_equals_numpy_step_test(histories: list, min_side: int) -> None:
    rng = np.random.default_rng(0)
    checked = 0
    for history in histories:
        model = StepModel(history, TleDetectorConfig())
        model.min_side = min_side
        gaps = np.arange(model.n - 1)
        cps = sorted(rng.choice(gaps, size=4, replace=False).tolist())
        for cut in ([], cps):
            ref_values, ref_factor = _reference(model, gaps, cut)
            lo, hi = segment_bounds_all(gaps, cut, model.n)
            values, n1, n2 = model.gaps(gaps, lo, hi)
            ok = np.isfinite(ref_factor)
            assert _same(values[ok], ref_values[ok])
            assert np.array_equal(ok, (n1 >= min_side) & (n2 >= min_side))
            for g in gaps[:: max(1, gaps.size // 7)]:
                steps, factor = model.gap(int(g), *segment_bounds(int(g), cut, model.n))
                assert factor == ref_factor[g] and [steps[k] for k in model.NAMES] == list(
                    ref_values[g] if ok[g] else np.zeros(len(model.NAMES))
                )
            checked += int(ok.sum())
    assert checked > 500


def test_kernel_propagates_nan_like_numpy(histories: list) -> None:
    model = StepModel(histories[0], TleDetectorConfig())
    model.stack = model.stack.copy()
    model.stack[2, model.n // 2] = np.nan
    gaps = np.arange(model.n - 1)
    ref_values, ref_factor = _reference(model, gaps, [])
    values, _, _ = model.gaps(gaps, *segment_bounds_all(gaps, [], model.n))
    ok = np.isfinite(ref_factor)
    assert np.isnan(ref_values[ok, 2]).any()
    assert _same(values[ok], ref_values[ok])


def _scalar_store(model: StepModel, g: int, cps: list[int]) -> dict[str, object]:
    """One gap stored with the per-gap scalar methods (step, sigmas, z, unexplained phase)."""
    steps, factor = model.gap(g, *segment_bounds(g, cps, model.n))
    if np.isinf(factor):
        return {"delta_a_m": 0.0, "delta_u_m": 0.0, "z_a": 0.0, "z_e": 0.0, "z_n": 0.0, "z_u": 0.0}
    sc = model.step_sigmas(g, factor)
    z_a, z_e, z_n, z_u = model.z(g, steps, factor, sc)
    return {
        "delta_a_m": steps["a_m"],
        "delta_e": [steps["ex"], steps["ey"]],
        "delta_normal_rad": [steps["i_rad"], steps["raan_resid_sin_i_rad"]],
        "delta_u_m": model.unexplained_phase_m(g, steps),
        "z_a": z_a,
        "z_e": z_e,
        "z_n": z_n,
        "z_u": z_u,
        "sigma_a_m": sc["a_m"],
        "sigma_n_rad": (0.5 * (sc["i_rad"] ** 2 + sc["raan_resid_sin_i_rad"] ** 2)) ** 0.5,
    }


@pytest.mark.parametrize("min_side", [3, 1])
def test_batch_fill_equals_scalar_gap_by_gap(histories: list, min_side: int) -> None:
    """The array store (one call a pass) against the scalar per-gap formulas, bit for bit."""
    model = StepModel(histories[1], TleDetectorConfig())
    model.min_side = min_side
    n_gaps = model.n - 1
    cps = [n_gaps // 3, n_gaps // 2]
    many = empty_steps(model.t, n_gaps)
    fill_gaps(many, model, np.arange(n_gaps), cps)
    one = empty_steps(model.t, n_gaps)
    for g in range(0, n_gaps, 2):  # a single-gap fill goes through the same store
        fill_gap(one, model, g, cps)
    inf_gaps = 0
    for g in range(n_gaps):
        ref = _scalar_store(model, g, cps)
        inf_gaps += int("sigma_a_m" not in ref)
        for name, value in ref.items():
            assert _same(getattr(many, name)[g], np.asarray(value)), (g, name)
            if g % 2 == 0:
                assert _same(getattr(one, name)[g], np.asarray(value)), (g, name)
    if min_side > 1:
        assert inf_gaps > 0  # the cut windows leave gaps untestable next to the change points
    assert n_gaps - inf_gaps > 50


def test_shared_rolling_rate_equals_recomputed(histories: list) -> None:
    model = StepModel(histories[2], TleDetectorConfig())
    for k in model.NAMES:
        y = model.s[k]
        rate = rolling_rate(model.t, y, 40)
        assert _same(robust_scale_rolling(y, 40, model.t, rate), robust_scale_rolling(y, 40, model.t))
        assert drift_noise_rate(model.t, y, 40, rate) == drift_noise_rate(model.t, y, 40)


def test_segment_bounds_all_matches_scalar() -> None:
    rng = np.random.default_rng(1)
    for _ in range(50):
        n = int(rng.integers(5, 60))
        cps = sorted(set(rng.integers(0, n - 1, size=int(rng.integers(0, 5))).tolist()))
        gaps = np.arange(n - 1)
        lo, hi = segment_bounds_all(gaps, cps, n)
        assert [(int(a), int(b)) for a, b in zip(lo, hi, strict=True)] == [segment_bounds(g, cps, n) for g in gaps]


def _checksum_by_definition(line: str) -> int:
    total = 0
    for ch in line[:68]:
        if ch.isdigit():
            total += int(ch)
        elif ch == "-":
            total += 1
    return total % 10


def test_checksum_equals_definition() -> None:
    # a published element set (the ISS, CelesTrak's TLE format page): check digits 7 and 7
    assert tle_checksum("1 25544U 98067A   08264.51782528 -.00002182  00000-0 -11606-4 0  2927") == 7
    assert tle_checksum("2 25544  51.6416 247.4627 0006703 130.5360 325.0288 15.72125391563537") == 7
    rnd = random.Random(5)
    alphabet = "0123456789-+. ABUZ\t\u00e9\u0663"  # a non-ASCII letter and an Arabic-Indic digit too
    for _ in range(3000):
        line = "".join(rnd.choice(alphabet) for _ in range(rnd.randint(0, 75)))
        assert tle_checksum(line) == _checksum_by_definition(line), repr(line)


def test_localise_kernel_equals_numpy(histories: list) -> None:
    rng = np.random.default_rng(2)
    compared = 0
    for history in histories:
        model = StepModel(history, TleDetectorConfig())
        n_gaps = model.n - 1
        for g in range(0, n_gaps, 3):
            lo, hi = (0, model.n) if g % 2 else segment_bounds(g, [max(0, g - 5), min(n_gaps - 1, g + 6)], model.n)
            weights = tuple(float(x) for x in rng.uniform(0.3, 2.0, 3))
            weight_u = float(rng.choice([0.0, 0.8]))
            fast = model.localise(g, lo, hi, weights, weight_u)  # type: ignore[arg-type]
            assert fast == model.localise_numpy(g, lo, hi, weights, weight_u), g  # type: ignore[arg-type]
            compared += 1
    assert compared > 200
