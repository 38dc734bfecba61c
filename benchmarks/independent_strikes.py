"""An independent strike generator for the flux-inference coverage study (no code shared with abrupt's Monte Carlo).

Written from the published formulas, apart from abrupt.flux and abrupt.rates.montecarlo/geometry:

* sizes: NASA-90/91 cumulative debris flux (Kessler et al. 1991 as in ECSS-E-ST-10-04C: Φ(h,S) Ψ(i)
  [H(d) F1(d) g1(t) + F2(d) g2(t)]) and Grün et al. 1985 (ECSS Eq. 101) at 1 AU, both ×4 from a tumbling
  plate to a cross-section; characteristic length drawn log-uniform with importance weights −dF/d ln d;
* masses: NASA-90/91's density law (4 g/cm³ to 0.62 cm, 2.8 d^-0.74 above) and 2.5 g/cm³ meteoroids;
* geometry: the spacecraft's box faces and two-sided panels (arrays rotated about their drive axis by
  U(0, π/2)); a face drawn ∝ its projected area toward the source, a point uniform on it, kept when a ray
  from it toward the source meets no other face (ray visibility), weight = the facing projected area;
* ΔH = r × ΔP, ΔP = −β m v d̂ (Bennett 2022 Eqs. 5.1-5.2), r from the bus centre, orbit frame;
* detection: logistic efficiency per day; Poisson strikes and Poisson false alarms (sizes logistic in
  ln|ΔH| about the efficiency midpoint, isotropic directions).

Taken from abrupt as data, not code paths of the inference: the speed/direction distributions of the
flux tables (Kessler crossing-orbit debris directions, meteoroid directions with Earth shielding and the
spacecraft's motion), the meteoroid Earth factor G·sf·K and the tabulated Ψ(i).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from abrupt.model.spacecraft import Spacecraft
from abrupt.rates.flux import METEOROID_DENSITY_KG_M3, meteoroid_earth_factors, nasa90_psi
from abrupt.rates.tables import DirectionBins, debris_crossing_directions, meteoroid_directions

SECONDS_PER_YEAR = 3.15576e7
R_EARTH_M = 6_378_000.0


def nasa90_tumbling(d_m: np.ndarray, h_km: float, inc_deg: float, year: float, s_sfu: float = 100.0) -> np.ndarray:
    """NASA-90/91 cumulative flux of diameter >= d on a tumbling surface [m^-2 yr^-1] (d in cm inside)."""
    d = d_m * 100.0
    phi1 = 10.0 ** (h_km / 200.0 - s_sfu / 140.0 - 1.5)
    g1 = 1.02 ** (year - 1988.0) if year < 2011 else 1.02**23 * 1.04 ** (year - 2011.0)
    g2 = 1.0 + 0.05 * (year - 1988.0)
    big_h = np.sqrt(10.0 ** np.exp(-((np.log10(d) - 0.78) ** 2) / 0.637**2))
    return (
        phi1 / (phi1 + 1.0) * nasa90_psi(inc_deg) * (big_h * 1.22e-5 * d**-2.5 * g1 + 8.1e10 * (d + 700.0) ** -6 * g2)
    )


def grun_1au(m_kg: np.ndarray) -> np.ndarray:
    """Grün cumulative meteoroid flux of mass >= m at 1 AU on a randomly oriented plate [m^-2 yr^-1]."""
    m = m_kg * 1e3
    f1 = (2.2e3 * m**0.306 + 15.0) ** -4.38
    f2 = 1.3e-9 * (m + 1e11 * m**2 + 1e27 * m**4) ** -0.36
    f3 = 1.3e-16 * (m + 1e6 * m**2) ** -0.85
    return SECONDS_PER_YEAR * (f1 + f2 + f3)


@dataclass
class Faces:
    """Rectangles: centre, normal, in-plane axes u and v, half sizes; two-sided panels rotate about u."""

    centre: np.ndarray  # (F, 3)
    normal: np.ndarray
    u: np.ndarray
    half: np.ndarray  # (F, 2)
    two_sided: np.ndarray  # (F,)
    rotates: np.ndarray  # (F,)


def faces_of(sc: Spacecraft) -> Faces:
    boxes = [s for s in sc.surfaces if s.shape == "box"]
    com = ([b for b in boxes if b.kind == "bus"] or boxes)[0].center_m
    c, n, u, h, two, rot = [], [], [], [], [], []
    for b in boxes:
        size = np.asarray(b.size_m, dtype=float)
        for a in range(3):
            a1, a2 = (a + 1) % 3, (a + 2) % 3
            for sign in (1.0, -1.0):
                e = np.zeros(3)
                e[a] = sign
                c.append(np.asarray(b.center_m) - com + e * size[a] / 2)
                n.append(e)
                uu = np.zeros(3)
                uu[a1] = 1.0
                u.append(uu)
                h.append([size[a1] / 2, size[a2] / 2])
                two.append(False)
                rot.append(False)
    for p in (s for s in sc.surfaces if s.shape == "panel"):
        c.append(np.asarray(p.center_m) - com)
        n.append(np.asarray(p.normal, dtype=float))
        u.append(np.asarray(p.u_axis, dtype=float))
        h.append(np.asarray(p.size_m, dtype=float) / 2)
        two.append(True)
        rot.append(p.kind == "solar_array")
    return Faces(np.array(c), np.array(n), np.array(u), np.array(h), np.array(two), np.array(rot))


def sample_directions(bins: DirectionBins, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    k = rng.choice(bins.weight.size, size=n, p=bins.weight / bins.weight.sum())
    speed = np.maximum(bins.speed_lo_mps[k] + rng.random(n) * (bins.speed_hi_mps[k] - bins.speed_lo_mps[k]), 1.0)
    az = bins.azimuth_lo_rad[k] + rng.random(n) * (bins.azimuth_hi_rad[k] - bins.azimuth_lo_rad[k])
    s_el = np.sin(bins.elevation_lo_rad[k]) + rng.random(n) * (
        np.sin(bins.elevation_hi_rad[k]) - np.sin(bins.elevation_lo_rad[k])
    )
    c_el = np.sqrt(np.clip(1.0 - s_el**2, 0.0, None))
    return speed, np.column_stack([s_el, c_el * np.cos(az), c_el * np.sin(az)])


def visible_points(
    faces: Faces, d: np.ndarray, angle: np.ndarray, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Points drawn ∝ projected area on the faces seen from d, and weight S(d)·1[unshadowed] per draw."""
    n = d.shape[0]
    c, u0, half = faces.centre, faces.u, faces.half
    ca, sa = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    n0 = np.broadcast_to(faces.normal, (n, *faces.normal.shape))
    ub = np.broadcast_to(u0, n0.shape)
    rotated = n0 * ca + np.cross(ub, n0) * sa + ub * np.sum(ub * n0, axis=2, keepdims=True) * (1 - ca)  # Rodrigues
    normal = np.where(faces.rotates[None, :, None], rotated, n0)
    v = np.cross(normal, ub)
    cos = np.einsum("nfk,nk->nf", normal, d)
    area = 4.0 * half[:, 0] * half[:, 1]
    proj = area[None, :] * np.where(faces.two_sided[None, :], np.abs(cos), np.maximum(cos, 0.0))
    total = proj.sum(axis=1)
    pick = np.argmax(np.cumsum(proj, axis=1) > (rng.random(n) * total)[:, None], axis=1)
    rows = np.arange(n)
    s, t = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    p = c[pick] + (s * half[pick, 0])[:, None] * ub[rows, pick] + (t * half[pick, 1])[:, None] * v[rows, pick]
    shadowed = np.zeros(n, dtype=bool)
    for g in range(c.shape[0]):
        dn = np.einsum("nk,nk->n", d, normal[:, g])
        with np.errstate(divide="ignore", invalid="ignore"):  # dn = 0: a face edge-on to the ray, never hit
            tg = np.einsum("nk,nk->n", c[g] - p, normal[:, g]) / dn
            q = p + tg[:, None] * d - c[g]
        inside = (np.abs(np.einsum("nk,nk->n", q, ub[:, g])) <= half[g, 0]) & (
            np.abs(np.einsum("nk,nk->n", q, v[:, g])) <= half[g, 1]
        )
        shadowed |= (pick != g) & (np.abs(dn) > 1e-12) & (tg > 1e-9) & inside
    return p, np.where(shadowed, 0.0, total)


@dataclass
class StrikeSample:
    """Unit-β strikes of one population on one spacecraft in one orbit: ΔH per draw and its rate [1/yr]."""

    dH_vec: np.ndarray  # (N, 3) orbit frame, β = 1 [N·m·s]
    rate: np.ndarray  # (N,) strikes per year carried by each draw


def strike_sample(
    sc: Spacecraft, population: str, altitude_km: float, inc_deg: float, year: float, n: int, seed: int
) -> StrikeSample:
    rng = np.random.default_rng(seed)
    faces = faces_of(sc)
    lo, hi = 3e-5, 0.1  # [m] characteristic length drawn log-uniform
    if population == "debris":
        bins = debris_crossing_directions(altitude_km * 1e3, inc_deg)

        def cum(d: np.ndarray) -> np.ndarray:
            return 4.0 * nasa90_tumbling(d, altitude_km, inc_deg, year)

        def mass(d: np.ndarray) -> np.ndarray:
            rho = np.where(d * 100 > 0.62, 2800.0 * (d * 100) ** -0.74, 4000.0)
            return math.pi / 6 * rho * d**3
    else:
        bins, _ = meteoroid_directions(altitude_km * 1e3)
        factor = meteoroid_earth_factors(altitude_km * 1e3).total

        def mass(d: np.ndarray) -> np.ndarray:
            return math.pi / 6 * METEOROID_DENSITY_KG_M3 * d**3

        def cum(d: np.ndarray) -> np.ndarray:
            return 4.0 * factor * grun_1au(mass(d))

    parts_h, parts_r = [], []
    chunk = 200_000
    for start in range(0, n, chunk):
        m = min(chunk, n - start)
        d = np.exp(rng.uniform(math.log(lo), math.log(hi), m))
        eps = 1e-4
        per_ln_d = (cum(d * math.exp(-eps)) - cum(d * math.exp(eps))) / (2 * eps)  # −dF/d ln d [m^-2 yr^-1]
        speed, direction = sample_directions(bins, m, rng)
        angle = rng.uniform(0.0, math.pi / 2, m)
        point, area = visible_points(faces, direction, angle, rng)
        dp = -(mass(d) * speed)[:, None] * direction
        parts_h.append(np.cross(point, dp))
        parts_r.append(per_ln_d * math.log(hi / lo) * area / n)
    return StrikeSample(np.concatenate(parts_h), np.concatenate(parts_r))


def draw_fleet(
    exposure: pd.DataFrame,
    samples: dict[tuple[float, float], dict[str, StrikeSample]],
    truth: dict[str, float],
    rng: np.random.Generator,
) -> pd.DataFrame:
    """Detected events of a fleet: Poisson strikes per spacecraft-day, logistic detection, Poisson false alarms."""
    rows = []
    f = exposure["analysed_fraction"].to_numpy()
    x50 = exposure["dH50_Nms"].to_numpy()
    k = exposure["efficiency_slope"].to_numpy()
    orbit = list(zip(exposure["altitude_km"], exposure["inclination_deg"], strict=True))
    for key in set(orbit):
        idx = np.flatnonzero([o == key for o in orbit])
        for pop, scale_key in (("debris", "debris_scale"), ("meteoroid", "meteoroid_scale")):
            smp = samples[key][pop]
            total = smp.rate.sum()
            counts = rng.poisson(f[idx] * truth[scale_key] * total / 365.25)
            day = np.repeat(idx, counts)
            pick = rng.choice(smp.rate.size, size=day.size, p=smp.rate / total)
            vec = truth["beta"] * smp.dH_vec[pick]
            size = np.linalg.norm(vec, axis=1)
            found = rng.random(day.size) < 1.0 / (1.0 + (x50[day] / size) ** k[day])
            rows.append((day[found], vec[found]))
    fa = rng.poisson(exposure["false_alarms_per_day"].to_numpy() * f)
    day = np.repeat(np.arange(len(exposure)), fa)
    size = x50[day] * np.exp(rng.logistic(size=day.size) / k[day])
    unit = rng.normal(size=(day.size, 3))
    rows.append((day, unit / np.linalg.norm(unit, axis=1, keepdims=True) * size[:, None]))
    day = np.concatenate([r[0] for r in rows])
    vec = np.concatenate([r[1] for r in rows])
    seconds = rng.uniform(0.0, 86_400.0 * f[day])
    times = pd.to_datetime(exposure["day"].to_numpy()[day]) + pd.to_timedelta(seconds, unit="s")
    return pd.DataFrame(
        {
            "spacecraft": exposure["spacecraft"].to_numpy()[day],
            "kind": "strike",
            "detector": exposure["detector"].to_numpy()[day],
            "time_utc": times.strftime("%Y-%m-%dT%H:%M:%S.%fZ"),
            "dH_Nms": np.linalg.norm(vec, axis=1),
            "dH_O_r_Nms": vec[:, 0],
            "dH_O_t_Nms": vec[:, 1],
            "dH_O_n_Nms": vec[:, 2],
        }
    )
