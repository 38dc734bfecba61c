"""Physical bounds on ρB from TLE decay: no-signal objects skipped, impossible windows refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.density import drag_plausibility as dp
from abrupt.density import tle_drag
from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history, wind_factor
from abrupt.readers.tle import MU_EARTH_WGS72_M3_S2, read_tle


def _tle_history(
    tmp_path: Path, a_m: float, incl_deg: float, noise: float, n_dot: float = 0.0, days: float = 20.0
) -> Path:
    """TLE text of a near-circular orbit of semi-major axis ``a_m``: n̄ grows at ``n_dot`` (rad/s²) with
    white noise of ``noise`` × n̄ on each set (two sets a day)."""
    from sgp4.api import WGS72, Satrec
    from sgp4.exporter import export_tle

    rng = np.random.default_rng(3)
    n0 = math.sqrt(MU_EARTH_WGS72_M3_S2 / a_m**3)
    lines = []
    for k, td in enumerate(np.arange(0.0, days, 0.5)):
        n = n0 + n_dot * td * 86400.0 + noise * n0 * rng.standard_normal()
        sat = Satrec()
        sat.sgp4init(
            WGS72, "i", 99002, 25000.0 + td, 1e-4, 0.0, 0.0, 1e-4, 0.0, math.radians(incl_deg), 0.0, n * 60.0, 0.0
        )
        sat.classification, sat.intldesg, sat.elnum, sat.revnum = "U", "18001A", k % 1000, 0
        lines += list(export_tle(sat))
    p = tmp_path / f"sat-{round(a_m / 1e3)}.tle"
    p.write_text("\n".join(lines) + "\n")
    return p


def test_wind_factor_bound_matches_the_corotating_atmosphere() -> None:
    """The bound 1 − 2x cos i + x² equals |v_rel|²/v² of a circular orbit at the ascending node,
    computed independently by ``wind_factor`` (F = |v_rel|(v_rel·v̂)/v²: the same there, v_rel ∥ v
    for i = 0); for a geostationary orbit (x = 1, i = 0) it is zero."""
    for r, incl in ((6778e3, 0.0), (26560e3, 0.0), (42000e3, 0.0)):
        v = math.sqrt(MU_EARTH_WGS72_M3_S2 / r)
        pos = np.array([[r, 0.0, 0.0]])
        vel = np.array([[0.0, v * math.cos(incl), v * math.sin(incl)]])
        x = dp.EARTH_ROTATION_RATE_RAD_S * r / v
        assert float(wind_factor(pos, vel)[0]) == pytest.approx(1 - 2 * x * math.cos(incl) + x**2, rel=1e-9)
    h_geo = (42164.17e3 - dp.WGS84_A_M) / 1e3
    geo = float(dp.max_decay_rate(np.array([h_geo]), 0.0)[0])
    polar = float(dp.max_decay_rate(np.array([h_geo]), math.pi / 2)[0])
    assert geo < 1e-6 * polar


def test_max_decay_rate_is_the_circular_drag_law() -> None:
    """dn/dt = (3/2) n ρ B v (circular orbit; da/dt = −ρ B v a) at the extreme density, with F = 1 at
    i = 90° and a negligible x² (low orbit: x² ≈ 0.004)."""
    h = 500.0
    alts, log_rho = dp.extreme_density_table()
    rho = math.exp(float(np.interp(h, alts, log_rho)))
    r = dp.WGS84_A_M + h * 1e3
    n, v = math.sqrt(MU_EARTH_WGS72_M3_S2 / r**3), math.sqrt(MU_EARTH_WGS72_M3_S2 / r)
    x = dp.EARTH_ROTATION_RATE_RAD_S * r / v
    expected = 1.5 * n * rho * dp.MAX_BALLISTIC_COEFFICIENT_M2_KG * v * (1 + x**2)
    assert float(dp.max_decay_rate(np.array([h]), math.pi / 2)[0]) == pytest.approx(expected, rel=1e-12)


def test_geostationary_history_is_skipped_with_its_reason(tmp_path: Path) -> None:
    history = read_tle(_tle_history(tmp_path, 42164.17e3, 2.0, noise=1e-7))
    res = rho_b_from_history(history, TleDragConfig(), maneuvers="none")
    assert len(res.windows) == 0
    assert res.skipped is not None and res.skipped.startswith("no drag signal above")
    ceiling = float(res.skipped.split()[4])
    assert 1000.0 < ceiling < 35786.0
    assert sum(n for k, n in res.repairs.counts.items() if "no drag signal" in k) == 1


def test_leo_history_windows_unchanged(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A noisy 400 km history is not skipped and its windows are bit-identical to those without the checks."""
    path = _tle_history(tmp_path, 6778e3, 51.6, noise=1e-7, n_dot=2e-14)
    cfg = TleDragConfig(interval_days=2.0)
    guarded = rho_b_from_history(read_tle(path), cfg, maneuvers="none")
    monkeypatch.setattr(tle_drag, "no_drag_signal", lambda *a: None)
    monkeypatch.setattr(tle_drag, "refuse_implausible", lambda frame: 0)
    plain = rho_b_from_history(read_tle(path), cfg, maneuvers="none")
    assert guarded.skipped is None and len(guarded.windows) > 5
    pd.testing.assert_frame_equal(guarded.windows, plain.windows, check_exact=True)


def test_window_refused_where_b_would_exceed_the_maximum() -> None:
    """B = K/ρ_M: a window whose K − 3σ over the model density exceeds B_max is refused; one whose
    lower bound allows B_max, a window without a model density and a negative one are left alone."""
    rho = 1e-12
    b_max = dp.MAX_BALLISTIC_COEFFICIENT_M2_KG
    frame = pd.DataFrame(
        {
            "rho_b_per_m": [3 * b_max * rho, 3 * b_max * rho, 1e3 * b_max * rho, 0.01 * rho, -5.0],
            "rho_b_sigma_per_m": [0.1 * b_max * rho, 0.8 * b_max * rho, 0.0, 0.001 * rho, 1.0],
            "model_density_kg_m3": [rho, rho, float("nan"), rho, rho],
            "status": ["ok", "ok", "ok", "ok", "negative decay"],
        }
    )
    assert dp.refuse_implausible(frame) == 1
    assert frame["status"].tolist() == [dp.IMPLAUSIBLE_STATUS, "ok", "ok", "ok", "negative decay"]


def test_cli_counts_the_skipped_object(tmp_path: Path) -> None:
    from click.testing import CliRunner

    import abrupt.cli.main  # noqa: F401  (registers every command group)
    from abrupt.cli.groups import cli

    path = _tle_history(tmp_path, 42164.17e3, 2.0, noise=1e-7)
    out = tmp_path / "w.csv"
    args = ["density", "tle", str(path), "--out", str(out), "--no-model", "--maneuvers", "none"]
    res = CliRunner().invoke(cli, args)
    assert res.exit_code == 0, res.output
    assert "1 object(s) skipped: no drag signal" in res.output
    assert "0 window(s) refused" in res.output
    assert "0 window(s) of 1 object(s)" in res.output
