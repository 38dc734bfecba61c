"""The 90 %-detectable ΔV: the GLR information C(θ) is the one a real jump meets, and the non-central
chi-square quantile is right."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from abrupt.detect.orbit.analysis import OrbitDetectorConfig, analyse
from abrupt.detect.orbit.ekf import FilterConfig
from abrupt.detect.orbit.sensitivity import detectable_dv, noncentrality
from abrupt.simulate.orbit import Impulse, OrbitSimulationConfig, simulate_orbit


@pytest.mark.parametrize(("threshold", "p_detect"), [(7.8, 0.9), (20.0, 0.9), (12.0, 0.5)])
def test_noncentrality_against_sampled_noncentral_chi_square(threshold: float, p_detect: float) -> None:
    lam = noncentrality(threshold, p_detect)
    rng = np.random.default_rng(1)
    z = rng.normal(size=(200_000, 3))
    z[:, 0] += np.sqrt(lam)  # |N(μ, I)|² with |μ|² = λ
    assert np.mean(np.sum(z**2, axis=1) > threshold) == pytest.approx(p_detect, abs=0.005)


def test_glr_of_a_noise_free_jump_equals_its_noncentrality() -> None:
    # Two-body truth and two-body filter, no noise: the innovations are the jump's own signature, so the
    # sliding GLR at the jump equals νᵀC(θ)ν exactly when C is the information the jump meets.
    step = 10.0
    t_jump = 3005.0  # mid-interval, as the statistic places the jump
    dv = np.array([0.004, -0.006, 0.003])
    sim = simulate_orbit(
        OrbitSimulationConfig(
            duration_s=6000.0, rate_hz=1 / step, sigma_pos_m=0.0, sigma_vel_mps=0.0, impulses=(Impulse(t_jump, dv),)
        )
    )
    cfg = OrbitDetectorConfig(
        filter=FilterConfig(tau_s=600.0, q_rtn_m2_s5=(1e-12,) * 3),
        sigma_pos_m=1.0,
        sigma_vel_mps=0.01,
        statistic="glr",
        settle_s=600.0,
        orbital_constants=False,
    )
    an = analyse(sim.ephemeris(), cfg)
    k = int(np.searchsorted(an.t_s, t_jump))
    assert an.glr_information is not None
    expected = float(dv @ an.glr_information[k] @ dv)
    assert an.statistics["glr"][k] == pytest.approx(expected, rel=0.02)
    # and the detectable |ΔV| at P_D 0.9: a jump of that size in the worst direction gives λ₉₀
    det = detectable_dv(an, threshold=stats.chi2.isf(1e-4, 3), p_detect=0.9)
    _, vec = np.linalg.eigh(0.5 * (an.glr_information[k] + an.glr_information[k].T))
    worst = det.worst_mps[k] * vec[:, 0]
    lam90 = noncentrality(stats.chi2.isf(1e-4, 3) / det.inflation, 0.9)
    assert float(worst @ an.glr_information[k] @ worst) / det.inflation == pytest.approx(lam90, rel=1e-6)
    assert det.best_mps[k] <= det.worst_mps[k]
