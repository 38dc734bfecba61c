"""Each element group's threshold from its own null (abrupt.detect.tle.group_thresholds)."""

from __future__ import annotations

import numpy as np
from scipy import stats

from abrupt.detect.tle.group_thresholds import own_null_gains, realised_group_rates

N_GAPS = 40_000
P_FA = 3e-3  # per gap, split to 1e-3 per group
GUARD = 8


def _gaussian_groups(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """z_a a |N(0,1)| step, z_e and z_n χ₂ magnitudes (2-D Gaussian vectors): the null of method step 2."""
    z_a = np.abs(rng.standard_normal(N_GAPS))
    z_e = np.hypot(rng.standard_normal(N_GAPS), rng.standard_normal(N_GAPS))
    z_n = np.hypot(rng.standard_normal(N_GAPS), rng.standard_normal(N_GAPS))
    return z_a, z_e, z_n


def test_gaussian_groups_get_the_gaussian_level_and_equal_gains() -> None:
    rng = np.random.default_rng(7)
    own = own_null_gains(*_gaussian_groups(rng), (1.0, 1.0, 1.0), GUARD, P_FA, "gpd")
    expected = float(stats.norm.isf(P_FA / 3 / 2))  # two-sided, budget split over three groups
    for t in own.thresholds:
        assert abs(t - expected) < 0.15 * expected
    assert all(0.8 < g < 1.25 for g in own.gains)


def test_a_heavier_normal_tail_gets_a_higher_threshold_and_a_smaller_gain() -> None:
    rng = np.random.default_rng(11)
    z_a, z_e, _ = _gaussian_groups(rng)
    # orbit-normal steps with a Student-t (3 d.o.f.) law per component: heavier tail than Gaussian
    z_n = np.hypot(stats.t.rvs(3, size=N_GAPS, random_state=rng), stats.t.rvs(3, size=N_GAPS, random_state=rng))
    own = own_null_gains(z_a, z_e, z_n, (1.0, 1.0, 1.0), GUARD, P_FA, "gpd")
    assert own.thresholds[2] > 1.3 * own.thresholds[0]
    assert own.gains[2] < 0.8
    # the realised rate of each group at its own threshold is near its share of the budget
    years = N_GAPS / 365.0
    rates = realised_group_rates(z_a, z_e, z_n, (1.0, 1.0, 1.0), own.thresholds, GUARD, years)
    share_per_year = P_FA / 3 * 365.0
    for name in ("a", "e", "n"):
        assert rates[name] < 2.5 * share_per_year


def test_north_south_burns_do_not_raise_the_normal_threshold() -> None:
    rng = np.random.default_rng(13)
    z_a, z_e, z_n = _gaussian_groups(rng)
    quiet = own_null_gains(z_a, z_e, z_n, (1.0, 1.0, 1.0), GUARD, P_FA, "gpd")
    burns = z_n.copy()
    burns[np.arange(500, N_GAPS, 800)] = 3000.0  # 50 north-south burns, thousands of σ (GEO)
    with_burns = own_null_gains(z_a, z_e, burns, (1.0, 1.0, 1.0), GUARD, P_FA, "gpd")
    assert with_burns.thresholds[2] < 1.2 * quiet.thresholds[2]
