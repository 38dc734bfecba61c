"""Attitude simulator (Bennett 2022 §2.1): conservation laws, analytic responses, noise and I/O."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from abrupt.errors import ConfigError
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike, simulate_attitude_batch
from abrupt.model.momentum import system_momentum
from abrupt.model.rotations import dcm_from_quaternion, normalise_quaternion
from abrupt.model.spacecraft import Spacecraft, bundled_spacecraft_path, load_spacecraft, spacecraft_from_dict
from abrupt.simulate.attitude import simulate_attitude, write_telemetry


@pytest.fixture(scope="module")
def thesis() -> Spacecraft:
    return load_spacecraft(bundled_spacecraft_path("thesis"))


def _inertial_momentum(sc: Spacecraft, state: dict[str, np.ndarray]) -> np.ndarray:
    return system_momentum(sc, state["q_BN"], state["omega_B_rad_s"], state["wheel_speed_rad_s"]).H_N_Nms


def test_particle_strike_momentum_is_lever_arm_cross_momentum() -> None:
    # Bennett 2022 §2.1.2: 10 mg at 8 km/s normal to a 1 m lever arm is 0.08 N m s; MEF scales it.
    s = Strike.from_particle(5.0, 10e-6, (0.0, 8000.0, 0.0), (0.0, 0.0, 1.0))
    assert s.magnitude_Nms == pytest.approx(0.08, rel=1e-12)
    np.testing.assert_allclose(s.dH_B_Nms, (-0.08, 0.0, 0.0), atol=1e-15)  # z × y = -x
    s2 = Strike.from_particle(5.0, 10e-6, (0.0, 8000.0, 0.0), (0.0, 0.0, 1.0), momentum_enhancement=2.5)
    assert s2.magnitude_Nms == pytest.approx(0.2, rel=1e-12)


def test_inertial_momentum_steps_by_applied_impulse_and_is_otherwise_conserved(thesis: Spacecraft) -> None:
    # Conservation law: without external torque ᴺH is constant; a strike steps it by ΔH_N (Eqs. 2.6-2.9).
    q0 = normalise_quaternion([0.9, 0.2, -0.3, 0.25])
    config = AttitudeSimConfig(
        duration_s=120.0,
        noise=False,
        initial_quaternion_BN=tuple(q0),
        initial_wheel_speed_rad_s=(120.0, -80.0, 60.0, 200.0),
    )
    strikes = [Strike(30.0, (0.31, -0.22, 0.17)), Strike(70.0, (-0.05, 0.6, 0.12))]
    result = simulate_attitude(thesis, config, strikes)
    state = result.true_state
    tel = result.telemetry  # noise-free telemetry, as a detector would read it
    h = system_momentum(
        thesis, tel[["q0", "q1", "q2", "q3"]], tel[["wx", "wy", "wz"]], tel[["rw1", "rw2", "rw3", "rw4"]]
    ).H_N_Nms
    t = state["t_s"]
    dh_n = result.truth[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy()
    # The truth's ΔH_N is ΔH_B rotated by the true attitude at the strike.
    for (_, row), dh in zip(result.truth.iterrows(), dh_n, strict=True):
        k = int(np.searchsorted(t, row["time_s"]))  # the sample at the start of the strike step
        bn = dcm_from_quaternion(state["q_BN"][k])
        np.testing.assert_allclose(bn.T @ [row["dH_B_x_Nms"], row["dH_B_y_Nms"], row["dH_B_z_Nms"]], dh, rtol=1e-9)
    segments = [(t <= 30.0), (t > 30.0) & (t <= 70.0), (t > 70.0)]
    expected = [h[0], h[0] + dh_n[0], h[0] + dh_n[0] + dh_n[1]]
    for mask, h_exp in zip(segments, expected, strict=True):
        err = np.abs(h[mask] - h_exp).max()
        assert err <= 1e-6 * np.linalg.norm(dh_n[0]), err
    step = h[np.searchsorted(t, 31.0)] - h[np.searchsorted(t, 29.0)]
    np.testing.assert_allclose(step, dh_n[0], rtol=0, atol=1e-6 * float(np.linalg.norm(dh_n[0])))


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_rates_settle_to_five_percent_of_peak_in_about_25_s(thesis: Spacecraft, axis: int) -> None:
    # Bennett 2022 §2.5.2.2: the strike response lasts about 25 s; spec Appendix A gains give ≈ 21 s.
    dh = [0.0, 0.0, 0.0]
    dh[axis] = 0.48  # 60 mg at 8 km/s, 1 m [N m s]
    strike = Strike(10.0, (dh[0], dh[1], dh[2]))
    result = simulate_attitude(thesis, AttitudeSimConfig(duration_s=80.0, noise=False), [strike])
    w = np.abs(result.true_state["omega_B_rad_s"][:, axis])
    t = result.true_state["t_s"]
    peak = w.max()
    last_above = t[np.nonzero(w > 0.05 * peak)[0].max()]
    settle_s = last_above - 10.0
    assert 15.0 <= settle_s <= 30.0, settle_s


def test_rate_just_after_strike_is_impulse_over_effective_inertia(thesis: Spacecraft) -> None:
    # Impulse balance: the wheels keep their absolute speed during the impulse, so ω⁺ = (J - G Js Gᵀ)⁻¹ ΔH.
    config = AttitudeSimConfig(duration_s=2.0, sim_rate_hz=100.0, telemetry_rate_hz=100.0, noise=False)
    dh = np.array([0.2, -0.3, 0.4])
    result = simulate_attitude(thesis, config, [Strike(1.0, tuple(dh))])
    g = thesis.wheel_axes
    j_eff = thesis.inertia_kgm2 - (g * thesis.wheel_spin_inertias_kgm2) @ g.T
    expected = np.linalg.solve(j_eff, dh)
    after = result.true_state["omega_B_rad_s"][101]  # one step after the strike step
    # Control acts for one step of 0.01 s: P Δt / J ≈ 0.4% reduction.
    np.testing.assert_allclose(after, expected, rtol=1e-2)


def test_small_strike_response_matches_linearised_closed_loop(thesis: Spacecraft) -> None:
    # Small-angle closed loop about x: J_eff θ̈ = -K σ - P θ̇ with σ ≈ θ/4 (MRP), θ̇(0⁺) = ΔH / J_eff.
    config = AttitudeSimConfig(duration_s=60.0, noise=False)
    dh = 0.08  # 10 mg [N m s]
    result = simulate_attitude(thesis, config, [Strike(5.0, (dh, 0.0, 0.0))])
    g = thesis.wheel_axes
    j_eff = (thesis.inertia_kgm2 - (g * thesis.wheel_spin_inertias_kgm2) @ g.T)[0, 0]
    k, p = config.gain_K_Nm, config.gain_P_Nms

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], (-k * y[0] / 4.0 - p * y[1]) / j_eff]

    t = result.true_state["t_s"]
    after = t >= 5.1
    sol = solve_ivp(rhs, (5.01, 60.0), [0.0, dh / j_eff], t_eval=t[after], rtol=1e-10, atol=1e-14)
    w = result.true_state["omega_B_rad_s"][after, 0]
    peak = np.abs(w).max()
    assert np.abs(w - sol.y[1]).max() <= 0.01 * peak
    # Peak wheel torque about x for 10 mg: spec §2.1 table gives 0.024 N m (unsaturated).
    wheel_x = result.true_state["wheel_speed_rad_s"][:, 0]
    torque = np.abs(np.diff(wheel_x)).max() / 0.1 * thesis.wheel_spin_inertias_kgm2[0]
    assert torque == pytest.approx(0.024, rel=0.2)


def test_wheel_torque_saturates_at_its_limit(thesis: Spacecraft) -> None:
    # 200 mg about x needs ≈ 0.48 N m from the wheels: every wheel is held at ±0.2 N m.
    config = AttitudeSimConfig(duration_s=20.0, sim_rate_hz=100.0, telemetry_rate_hz=100.0, noise=False)
    result = simulate_attitude(thesis, config, [Strike(1.0, (1.6, 0.0, 0.0))])
    st = result.true_state
    g = thesis.wheel_axes
    js = thesis.wheel_spin_inertias_kgm2
    absolute = st["wheel_speed_rad_s"] + st["omega_B_rad_s"] @ g  # gᵀω + Ω
    torque = np.diff(absolute, axis=0) * 100.0 * js  # Eq. 2.3: Js (gᵀω̇ + Ω̇) = u
    assert np.abs(torque).max() <= 0.2 * (1 + 1e-6)
    assert np.abs(torque[:, 0]).max() >= 0.2 * (1 - 1e-6)


def test_noise_free_telemetry_equals_true_state(thesis: Spacecraft) -> None:
    result = simulate_attitude(thesis, AttitudeSimConfig(duration_s=10.0, noise=False), [Strike(2.0, (0.1, 0, 0))])
    tel = result.telemetry
    np.testing.assert_array_equal(tel[["q0", "q1", "q2", "q3"]].to_numpy(), result.true_state["q_BN"])
    np.testing.assert_array_equal(tel[["wx", "wy", "wz"]].to_numpy(), result.true_state["omega_B_rad_s"])
    np.testing.assert_array_equal(tel[["rw1", "rw2", "rw3", "rw4"]].to_numpy(), result.true_state["wheel_speed_rad_s"])


def test_telemetry_noise_has_the_configured_sigma(thesis: Spacecraft) -> None:
    config = AttitudeSimConfig(duration_s=600.0, seed=3)
    result = simulate_attitude(thesis, config)
    tel = result.telemetry
    st = result.true_state
    rate_err = tel[["wx", "wy", "wz"]].to_numpy() - st["omega_B_rad_s"]
    wheel_err = tel[["rw1", "rw2", "rw3", "rw4"]].to_numpy() - st["wheel_speed_rad_s"]
    quat_err = tel[["q1", "q2", "q3"]].to_numpy() - st["q_BN"][:, 1:]
    n = rate_err.size
    tol = 4.0 / np.sqrt(2 * n)  # about 4 standard errors of a sample sigma
    assert rate_err.std() == pytest.approx(4e-5, rel=tol)
    assert wheel_err.std() == pytest.approx(0.25, rel=tol)
    assert quat_err.std() == pytest.approx(7e-5, rel=tol)
    # Telemetry quaternions are unit with q0 >= 0.
    q = tel[["q0", "q1", "q2", "q3"]].to_numpy()
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    assert (q[:, 0] >= 0).all()
    assert list(tel.columns) == ["time", "q0", "q1", "q2", "q3", "wx", "wy", "wz", "rw1", "rw2", "rw3", "rw4"]
    assert str(tel["time"].dtype) == "datetime64[ns, UTC]"
    assert (tel["time"].diff().iloc[1:] == pd.Timedelta(milliseconds=100)).all()


def test_process_noise_makes_momentum_random_walk_with_configured_sigma(thesis: Spacecraft) -> None:
    # Rate random walk of σ per step changes body momentum by J σ per step (Table 2.1 state noise).
    config = AttitudeSimConfig(duration_s=400.0, seed=5, state_noise_rate_rad_s=1e-6, torque_noise_Nm=0.0)
    st = simulate_attitude(thesis, config).true_state
    h = _inertial_momentum(thesis, st)
    dh = np.diff(h[::10], axis=0)  # 1 s increments = 100 steps
    expected = np.sqrt(100) * 1e-6 * np.diag(thesis.inertia_kgm2)
    np.testing.assert_allclose(dh.std(axis=0), expected, rtol=0.15)


def test_same_seed_reproduces_and_different_seed_differs(thesis: Spacecraft) -> None:
    a = simulate_attitude(thesis, AttitudeSimConfig(duration_s=5.0, seed=11)).telemetry
    b = simulate_attitude(thesis, AttitudeSimConfig(duration_s=5.0, seed=11)).telemetry
    c = simulate_attitude(thesis, AttitudeSimConfig(duration_s=5.0, seed=12)).telemetry
    pd.testing.assert_frame_equal(a, b)
    assert not np.allclose(a["wx"], c["wx"])


def test_batch_runs_equal_single_runs_with_the_same_seeds(thesis: Spacecraft) -> None:
    config = AttitudeSimConfig(duration_s=30.0)
    strikes = [[Strike(10.0, (0.2, 0.0, 0.0))], [], [Strike(20.0, (0.0, 0.1, 0.3)), Strike(5.0, (0.1, 0, 0))]]
    seeds = [4, 5, 6]
    batch = simulate_attitude_batch(thesis, config, strikes, seeds)
    assert batch["q_BN"].shape == (3, config.n_samples, 4)
    for r in range(3):
        single = simulate_attitude(thesis, AttitudeSimConfig(duration_s=30.0, seed=seeds[r]), strikes[r])
        np.testing.assert_array_equal(batch["omega_B_rad_s"][r], single.telemetry[["wx", "wy", "wz"]].to_numpy())
        np.testing.assert_array_equal(batch["true_wheel_speed_rad_s"][r], single.true_state["wheel_speed_rad_s"])
        n = len(strikes[r])
        np.testing.assert_array_equal(
            batch["strike_dH_N_Nms"][r, :n],
            single.truth[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy(),
        )


def test_tachometer_discretisation_quantises_wheel_telemetry(thesis: Spacecraft) -> None:
    res = 2 * np.pi / 60.0  # 1 rpm [rad/s]
    tel = simulate_attitude(thesis, AttitudeSimConfig(duration_s=5.0, wheel_speed_resolution_rad_s=res)).telemetry
    counts = tel[["rw1", "rw2", "rw3", "rw4"]].to_numpy() / res
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-9)


def test_telemetry_is_written_in_the_spacecraft_files_units_and_convention() -> None:
    text = Path(bundled_spacecraft_path("thesis")).read_text()

    data = tomllib.loads(text)
    data["telemetry"]["wheel_speed"]["unit"] = "rpm"
    data["telemetry"]["body_rate"]["unit"] = "deg/s"
    data["telemetry"]["quaternion"]["order"] = "scalar_last"
    sc = spacecraft_from_dict(data)
    result = simulate_attitude(sc, AttitudeSimConfig(duration_s=20.0, noise=False), [Strike(1.0, (0.3, 0.2, 0.1))])
    tel = result.telemetry
    st = result.true_state
    np.testing.assert_allclose(tel[["rw1", "rw2", "rw3", "rw4"]].to_numpy(), st["wheel_speed_rad_s"] * 60 / (2 * np.pi))
    np.testing.assert_allclose(tel[["wx", "wy", "wz"]].to_numpy(), np.degrees(st["omega_B_rad_s"]))
    # scalar_last: column q0 of the file holds the first vector component.
    np.testing.assert_allclose(tel[["q0", "q1", "q2", "q3"]].to_numpy(), st["q_BN"][:, [1, 2, 3, 0]])


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_written_telemetry_round_trips(thesis: Spacecraft, tmp_path: Path, suffix: str) -> None:
    result = simulate_attitude(thesis, AttitudeSimConfig(duration_s=5.0, seed=1), [Strike(2.5, (0.1, 0.2, 0.0))])
    path, truth_path = write_telemetry(result, tmp_path / f"tlm{suffix}")
    assert truth_path == tmp_path / "tlm_truth.csv"
    back = pd.read_csv(path, dtype=str) if suffix == ".csv" else pd.read_parquet(path)
    assert list(back.columns) == list(result.telemetry.columns)
    # the values as written, parsed by Python's correctly rounded float() (pandas' own CSV float parser
    # differs between releases in the last bit)
    wx = np.array([float(x) for x in back["wx"]])
    np.testing.assert_array_equal(wx, result.telemetry["wx"].to_numpy())
    times = pd.to_datetime(back["time"], utc=True)
    np.testing.assert_array_equal(times.to_numpy(), result.telemetry["time"].to_numpy())
    if suffix == ".csv":
        assert back["time"].iloc[1] == "2026-01-01T00:00:00.100000Z"
    truth = pd.read_csv(truth_path)
    assert truth["time_utc"].iloc[0] == "2026-01-01T00:00:02.500000Z"
    assert truth["dH_Nms"].iloc[0] == pytest.approx(np.hypot(0.1, 0.2))


def test_write_telemetry_rejects_unknown_suffix(thesis: Spacecraft, tmp_path: Path) -> None:
    result = simulate_attitude(thesis, AttitudeSimConfig(duration_s=1.0))
    with pytest.raises(ConfigError, match=r"\.csv or \.parquet"):
        write_telemetry(result, tmp_path / "tlm.txt")


def test_invalid_configuration_is_rejected_with_the_key_named(thesis: Spacecraft) -> None:
    with pytest.raises(ConfigError, match="telemetry_rate_hz"):
        AttitudeSimConfig(sim_rate_hz=100.0, telemetry_rate_hz=30.0)
    with pytest.raises(ConfigError, match="duration_s"):
        AttitudeSimConfig(duration_s=-1.0)
    with pytest.raises(ConfigError, match="initial_quaternion_BN"):
        AttitudeSimConfig(initial_quaternion_BN=(1.0, 1.0, 0.0, 0.0))
    with pytest.raises(ConfigError, match="strikes"):
        simulate_attitude(thesis, AttitudeSimConfig(duration_s=10.0), [Strike(10.0, (0.1, 0, 0))])
    with pytest.raises(ConfigError, match="initial_wheel_speed_rad_s"):
        simulate_attitude(thesis, AttitudeSimConfig(duration_s=1.0, initial_wheel_speed_rad_s=(1.0, 2.0)))
    with pytest.raises(ValueError, match="finite"):
        Strike(1.0, (np.nan, 0.0, 0.0))
