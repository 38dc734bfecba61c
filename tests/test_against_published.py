"""Published figures the reproductions define, recomputed with fixed seeds and pinned as golden outputs.

Each test recomputes one figure, compares it with its golden file (``tests/golden/``, see
``tests/golden.py``) and with the published value within the stated tolerance:

* Bennett 2022 §2.4.2: the summation filter's threshold at P_fa = 1e-4 (Gaussian fit of 40,000
  event-free points) is 8.8; the reproduction's target is 8.8 ± 0.5 (``bench_attitude_detection.py --part a``);
* Dabrowski 2003 §4.1-4.2: the SIMSAT yaw step overshoots 0 %, about 4 % and about 20 % at 0.5°, 1°
  and 2° (``bench_dabrowski.py``);
* Kaderali 2021 Table 4.2: an apogee transverse burn of 1-100 m/s seen from Ascension gives K_max
  30-85 dB and a log fit with R² 0.981 (``bench_tracking_reproduction.py``, continuous-tracking preset).
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from abrupt.detect.attitude.change_detection import WindowConfig, sliding_statistic
from abrupt.detect.tracking.kaderali import fit_characterisation, run_kaderali_filter
from abrupt.model.attitude_dynamics import AttitudeSimConfig
from abrupt.model.momentum import system_momentum
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.model.stations import ascension
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.readers.telemetry import telemetry_from_frame
from abrupt.simulate.attitude import simulate_attitude
from abrupt.simulate.tracking import TrackingScenario, simulate_tracking, thesis_burn
from abrupt.thresholds import fit_threshold
from golden import check_golden
from reproductions.simsat import Maneuver, SimsatParams, simulate_simsat


def test_summation_threshold_reproduces_bennett_2022_section_2_4_2() -> None:
    sc = load_spacecraft(bundled_spacecraft_path())
    windows = WindowConfig(pre=200, post=180, cusum_delta_mu_Nms=0.1)  # the thesis's windows
    thresholds = []
    for seed in range(1000, 1010):  # the seeds of bench_attitude_detection.py --part a
        sim = simulate_attitude(sc, AttitudeSimConfig(duration_s=4038.0, seed=seed), [])
        tel = telemetry_from_frame(sim.telemetry, sc)
        h = system_momentum(sc, tel.quaternion_BN, tel.body_rate_rad_s, tel.wheel_speed_rad_s).H_N_Nms
        y = sliding_statistic("summation", h[:, :1], windows)[:, 0]
        y = y[np.isfinite(y)][:40000]
        assert y.size == 40000
        thresholds.append(fit_threshold(y, p_fa=1e-4, method="gaussian").value)
    check_golden("bennett2022_summation_threshold", {"thresholds": thresholds})
    assert abs(np.mean(thresholds) - 8.8) <= 0.5  # thesis 8.8, target ± 0.5
    # and the analytic value for white noise of the thesis's σ = 0.129 N·m·s: z(1e-4) σ sqrt(post + post²/pre)
    analytic = stats.norm.isf(1e-4) * 0.129 * math.sqrt(180 + 180**2 / 200)
    assert abs(np.mean(thresholds) - analytic) <= 0.5


def test_simsat_overshoot_reproduces_dabrowski_2003() -> None:
    p = SimsatParams()
    overshoot = []
    for amplitude in (0.5, 1.0, 2.0):
        m = Maneuver.thesis(amplitude)
        s = simulate_simsat(p, m)
        step = (s["t_s"] >= 15) & (s["t_s"] < 15 + m.step_period_s)
        overshoot.append(100 * (s["yaw_true_rad"][step, 0].max() / math.radians(amplitude) - 1))
    check_golden("dabrowski2003_simsat_overshoot", {"overshoot_percent": overshoot})
    # thesis: 0 %, about 4 %, about 20 % (spec §4.1-4.2 tolerances: < 0.5 %, 2-6 %, 15-30 %)
    assert overshoot[0] < 0.5 and 2.0 < overshoot[1] < 6.0 and 15.0 < overshoot[2] < 30.0


def test_apogee_transverse_k_max_reproduces_kaderali_2021_table_4_2() -> None:
    dv_grid = (1.0, 5.0, 10.0, 25.0, 50.0, 75.0, 100.0)  # [m/s]
    k_max = []
    for dv in dv_grid:
        scenario = TrackingScenario(stations=(ascension(-90.0),), burns=(thesis_burn("apogee", "S", dv),))
        sim = simulate_tracking(scenario, seed=1)
        result = run_kaderali_filter(TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc), sim.initial_state)
        k_max.append(result.k_max)
    fit = fit_characterisation(dv_grid, np.array(k_max), "log")
    check_golden("kaderali2021_apogee_transverse", {"k_max_db": k_max, "log_fit_r2": [fit.r2]})
    # Thesis: K_max 30-85 over 1-100 m/s, log-fit R² 0.981. It states no tolerance; ours: every burn
    # above the thesis's detection level K_th = 30.127, the 100 m/s value within 5 % of 85, R² ≥ 0.95.
    assert min(k_max) > 30.127
    assert abs(max(k_max) - 85.0) <= 0.05 * 85.0
    assert np.all(np.diff(k_max) > 0)  # K grows with the burn, as in Fig. 4.8
    assert fit.r2 >= 0.95
