"""Is the shared LAGEOS-1 CPF a dynamically consistent orbit in IERS ITRF? abrupt's force model fitted to it.

The audit's laser case simulates normal points from the CPF prediction and asks abrupt to fit them; a
post-fit range RMS of metres there is either abrupt's model or the CPF. This benchmark takes the ranges
out: it fits abrupt's orbit (state + radiation-pressure scale, eighth-order integration at 60 s) to the
CPF's own positions, turned inertial with abrupt's Earth orientation (IAU 2006/2000A, polar motion and
UT1 from astropy's bundled IERS table), and prints the 3-D RMS after each step:

1. abrupt's Earth orientation against astropy's ITRS→GCRS on the CPF epochs (the frame chain);
2. the laser force model (EGM2008 20×20, Sun, Moon, SRP with a conical shadow);
3. + solid Earth tides and the Schwarzschild term; + degree 40;
4. + a constant rotation of the CPF's Earth-fixed frame about its x and y axes (a pole offset);
5. + an Earth-rotation angle drifting in time (a UT1 error, linear and quadratic).

Steps 4-5 estimate how the CPF's terrestrial frame departs from IERS ITRF; a residual that only such
frame parameters remove is in the CPF, not in the dynamics.

Usage: ``python benchmarks/bench_slr_cpf_dynamics.py`` (needs ../shared/data; about 2 CPU-min).
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import astropy.units as u
import numpy as np
from astropy.coordinates import GCRS, ITRS, CartesianRepresentation
from astropy.time import Time

from _slr_from_cpf import read_cpf
from abrupt.model.orbit import ForceContext, ForceModel
from abrupt.model.orbit.propagation import propagate_with_stm
from abrupt.model.timescales import offline_astropy
from abrupt.model.tracking_measurements import earth_rotation_matrices
from abrupt.pipelines.laser_ranging import LASER_FORCE

CPF = Path(__file__).resolve().parents[2] / "shared" / "data" / "tracking" / "ilrs-corpus"
CPF = CPF / "lageos1_cpf_180613_16401.hts"
ARCSEC = np.pi / 180.0 / 3600.0
OMEGA_EARTH_RAD_S = 7.292115e-5


def fit_positions(
    t_s: np.ndarray, itrf_m: np.ndarray, c_fi: np.ndarray, force: ForceModel, epoch: np.datetime64, frame_terms: int
) -> tuple[float, np.ndarray, float]:
    """Gauss-Newton fit of state, SRP scale and ``frame_terms`` frame parameters (0, 2: pole offset x, y
    [rad]; 4: + Earth-rotation drift [rad/day, rad/day²]) to Earth-fixed positions; returns the 3-D RMS
    [m], the frame parameters and the SRP scale."""
    r_obs = np.einsum("nji,nj->ni", c_fi, itrf_m)
    x = np.concatenate([r_obs[0], (r_obs[1] - r_obs[0]) / (t_s[1] - t_s[0])])
    srp, frame = 1.0, np.zeros(frame_terms)
    days = t_s / 86400.0
    axes = [np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]), np.array([0, 0, 1.0])]
    powers = [0, 0, 1, 2]
    rms = np.inf
    for _ in range(8):
        ctx = ForceContext.build(replace(force, srp_scale=srp), epoch, -86400.0, float(t_s[-1]) + 86400.0)
        states, stm, sens = propagate_with_stm(
            x, 0.0, t_s, force=ctx, max_step_s=60.0, method="rk8", parameters=("srp_scale",)
        )
        ef = np.einsum("nij,nj->ni", c_fi, states[:, :3])
        theta = sum((frame[k] * days ** powers[k])[:, None] * axes[k] for k in range(frame_terms)) + 0 * ef
        res = np.einsum("nji,nj->ni", c_fi, itrf_m - ef - np.cross(theta, ef))
        cols = [stm[:, :3, :], sens[:, :3, 3:]]
        cols += [
            np.einsum("nji,nj->ni", c_fi, np.cross(axes[k], ef) * (days ** powers[k])[:, None])[:, :, None]
            for k in range(frame_terms)
        ]
        jac = np.concatenate(cols, axis=2).reshape(-1, 7 + frame_terms)
        step, *_ = np.linalg.lstsq(jac, res.reshape(-1), rcond=None)
        x, srp, frame = x + step[:6], srp + step[6], frame + step[7:]
        new_rms = float(np.sqrt(np.mean(np.sum(res**2, axis=1))))
        if abs(new_rms - rms) < 1e-4 * new_rms:
            break
        rms = new_rms
    return new_rms, frame, srp


def frame_rotation_rad(t_s: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """θ(t) (n, 3) [rad] of the frame parameters of :func:`fit_positions`: r_CPF ≈ r_ITRF + θ × r_ITRF."""
    days = np.asarray(t_s, float) / 86400.0
    theta = np.zeros((days.size, 3))
    theta[:, 0] = frame[0]
    theta[:, 1] = frame[1]
    if frame.size == 4:
        theta[:, 2] = frame[2] * days + frame[3] * days**2
    return theta


def main() -> None:
    offline_astropy()
    cpf = read_cpf(CPF)
    epoch = cpf.times_utc[0]
    t_s = cpf.seconds(cpf.times_utc)
    print(f"CPF: {CPF.name}, {t_s.size} positions over {t_s[-1] / 86400:.2f} days")
    c_fi = earth_rotation_matrices(t_s, model="iers", epoch_utc=epoch)
    ours = np.einsum("nji,nj->ni", c_fi, cpf.position_m)
    obstime = Time(cpf.times_utc, scale="utc", format="datetime64")
    itrs = ITRS(CartesianRepresentation(cpf.position_m.T * u.m), obstime=obstime)
    theirs = itrs.transform_to(GCRS(obstime=obstime)).cartesian.xyz.to_value(u.m).T
    worst_m = np.abs(ours - theirs).max()
    print(f"1. abrupt's ITRF->GCRF against astropy's ITRS->GCRS: largest difference {worst_m:.1e} m")
    tides = replace(LASER_FORCE, solid_tides=True, relativity=True)
    steps = [
        ("2. laser force model (EGM2008 20x20, Sun, Moon, SRP)", LASER_FORCE, 0),
        ("3. + solid Earth tides + Schwarzschild", tides, 0),
        ("3. + solid Earth tides + Schwarzschild, degree 40", replace(tides, gravity_degree=40), 0),
        ("4. + constant pole offset of the CPF frame", tides, 2),
        ("5. + Earth-rotation drift (linear, quadratic)", tides, 4),
    ]
    for label, force, n_frame in steps:
        start = time.process_time()
        rms, frame, srp = fit_positions(t_s, cpf.position_m, c_fi, force, epoch, n_frame)
        line = f"{label}: 3-D RMS {rms:.3f} m, SRP scale {srp:.3f}"
        if n_frame >= 2:
            line += f"; pole offset ({frame[0] / ARCSEC:+.4f}, {frame[1] / ARCSEC:+.4f}) arcsec"
        if n_frame == 4:
            line += (
                f"; UT1 drift {frame[2] / OMEGA_EARTH_RAD_S * 1e3:+.3f} ms/day,"
                f" {frame[3] / OMEGA_EARTH_RAD_S * 1e3:+.3f} ms/day^2"
            )
        print(f"{line} ({time.process_time() - start:.0f} CPU-s)", flush=True)


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_slr_cpf_dynamics", variant({})):
        main()
