"""Spacecraft strike geometry: where a particle from a given direction hits (Bennett 2022 §5.3.3.6).

The geometry comes from the ``[[surfaces]]`` of a spacecraft file (:mod:`abrupt.model.spacecraft`):
axis-aligned boxes (bus) and flat two-sided panels (solar arrays). Solar-array panels can rotate about
their ``u_axis`` (the array drive axis; the thesis rotates arrays about b_y) by a per-draw angle.

Two strike-location methods, both giving a point uniformly distributed over the silhouette the
spacecraft presents to the incoming flow, and the forward-most surface point there:

* ``silhouette`` (default, exact): sample a point uniformly in the bounding rectangle of the projected
  geometry on the plane normal to the incoming direction (the thesis's Q-R plane), cast a ray along the
  flow, keep the first surface hit, reject misses. This is the thesis algorithm in the limit of zero
  grid spacing, and is fast enough for millions of draws (numba).
* ``point_cloud`` (thesis): grid points on every face and panel, projected on the Q-R plane,
  rasterised at the grid spacing; a flagged cell is drawn uniformly (Q-slice by its cell count, then a
  uniform R-cell), and the forward-most point mapping to it is the strike point (spec §6.8 steps 1-6).

Frames: body B = orbit frame O in the trades (x radial o_r, y along-track o_θ, z orbit normal o_h).
``direction`` arguments are unit vectors toward where the particle comes *from* (v̂1 of the thesis's
frame V, i.e. minus the unit relative velocity). Positions are measured from the centre of mass, taken
at the geometric centre of the first bus box unless given.

* ``visible`` (the flux forward model's): face sampling with ray visibility (:func:`visible_strikes`): a
  point drawn on the surfaces facing the flow in proportion to their projected area, weighted by that
  area when nothing shadows it. Unlike the two above, which place a strike on the silhouette of a direction
  drawn by flux alone, its weights make the strike directions ∝ flux × visible area per direction.

Effective area: :func:`thesis_effective_area_m2` (Eqs. 5.15-5.18) and the flux-weighted mean silhouette
area :func:`mean_silhouette_area_m2` (spec erratum A14 option).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from abrupt.errors import ConfigError
from abrupt.model.spacecraft import Spacecraft


@dataclass(frozen=True)
class Geometry:
    """Boxes and panels in body axes, positions relative to the centre of mass [m]."""

    box_lo: NDArray[np.float64]  # (nb, 3)
    box_hi: NDArray[np.float64]  # (nb, 3)
    panel_center: NDArray[np.float64]  # (np, 3)
    panel_normal: NDArray[np.float64]  # (np, 3) at zero array angle
    panel_u: NDArray[np.float64]  # (np, 3) rotation (drive) axis, along size[0]
    panel_half: NDArray[np.float64]  # (np, 2) half sizes along u and v = n × u
    panel_rotates: NDArray[np.bool_]  # (np,) solar arrays rotate with the array angle
    panel_is_array: NDArray[np.bool_]  # (np,) for the MEF model

    @property
    def smallest_dimension_m(self) -> float:
        dims = [*(self.box_hi - self.box_lo).ravel(), *(2 * self.panel_half).ravel()]
        return float(min(dims))

    def scaled(self, factor: float) -> Geometry:
        """The same shape scaled by ``factor`` in length (area × factor²)."""
        return Geometry(
            self.box_lo * factor,
            self.box_hi * factor,
            self.panel_center * factor,
            self.panel_normal,
            self.panel_u,
            self.panel_half * factor,
            self.panel_rotates,
            self.panel_is_array,
        )


def geometry_from_spacecraft(spacecraft: Spacecraft, *, com_m: NDArray[np.float64] | None = None) -> Geometry:
    """Build the strike geometry from a spacecraft's ``[[surfaces]]``; error when it has none."""
    if not spacecraft.surfaces:
        raise ConfigError(
            "spacecraft has no [[surfaces]]; strike rates need its geometry (box bus, panel arrays)",
            file=spacecraft.source,
            key="surfaces",
        )
    boxes = [s for s in spacecraft.surfaces if s.shape == "box"]
    panels = [s for s in spacecraft.surfaces if s.shape == "panel"]
    if com_m is None:
        bus = [s for s in boxes if s.kind == "bus"] or boxes
        com = bus[0].center_m if bus else np.mean([p.center_m for p in panels], axis=0)
    else:
        com = np.asarray(com_m, dtype=np.float64)
    box_lo = np.array([s.center_m - s.size_m / 2 - com for s in boxes]).reshape(-1, 3)
    box_hi = np.array([s.center_m + s.size_m / 2 - com for s in boxes]).reshape(-1, 3)
    pc = np.array([p.center_m - com for p in panels]).reshape(-1, 3)
    pn = np.array([p.normal for p in panels], dtype=np.float64).reshape(-1, 3)
    pu = np.array([p.u_axis for p in panels], dtype=np.float64).reshape(-1, 3)
    ph = np.array([p.size_m / 2 for p in panels]).reshape(-1, 2)
    arr = np.array([p.kind == "solar_array" for p in panels], dtype=np.bool_)
    return Geometry(box_lo, box_hi, pc, pn, pu, ph, arr.copy(), arr)


def thesis_effective_area_m2(geometry: Geometry) -> float:
    """A_eff = L_c,bus² + ½ Σ L_SA W_SA, L_c,bus = (X+Y+Z)/3 (Bennett 2022 Eqs. 5.15-5.18, erratum A14)."""
    area = 0.0
    for lo, hi in zip(geometry.box_lo, geometry.box_hi, strict=True):
        area += (float(np.sum(hi - lo)) / 3.0) ** 2
    for half in geometry.panel_half:
        area += 0.5 * float(4.0 * half[0] * half[1])
    return area


# ----------------------------------------------------------------------------------------------
# numba kernels
# ----------------------------------------------------------------------------------------------


@numba.njit(cache=True)
def _frame(d: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Q (in the body x-y plane, ⟂ d) and R = d × Q of the thesis frame V."""
    q = np.empty(3)
    r = np.empty(3)
    _frame_into(d, q, r)
    return q, r


@numba.njit(cache=True)
def _frame_into(d, q, r):
    n = math.sqrt(d[0] * d[0] + d[1] * d[1])
    if n < 1e-12:
        q[0], q[1], q[2] = 1.0, 0.0, 0.0
    else:
        q[0], q[1], q[2] = -d[1] / n, d[0] / n, 0.0
    r[0] = d[1] * q[2] - d[2] * q[1]
    r[1] = d[2] * q[0] - d[0] * q[2]
    r[2] = d[0] * q[1] - d[1] * q[0]


@numba.njit(cache=True)
def _rotate_panels_into(angle, pn0, pu, prot, pn, pv):
    """Panel normals and v-axes (n × u) after rotating rotating panels by ``angle`` about u (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    for j in range(pn0.shape[0]):
        n0, n1, n2 = pn0[j, 0], pn0[j, 1], pn0[j, 2]
        u0, u1, u2 = pu[j, 0], pu[j, 1], pu[j, 2]
        if prot[j]:
            x0, x1, x2 = u1 * n2 - u2 * n1, u2 * n0 - u0 * n2, u0 * n1 - u1 * n0
            udn = u0 * n0 + u1 * n1 + u2 * n2
            n0, n1, n2 = (
                n0 * c + x0 * s + u0 * udn * (1.0 - c),
                n1 * c + x1 * s + u1 * udn * (1.0 - c),
                n2 * c + x2 * s + u2 * udn * (1.0 - c),
            )
        pn[j, 0], pn[j, 1], pn[j, 2] = n0, n1, n2
        pv[j, 0] = n1 * u2 - n2 * u1
        pv[j, 1] = n2 * u0 - n0 * u2
        pv[j, 2] = n0 * u1 - n1 * u0


@numba.njit(cache=True)
def _rotated_panels(angle, pn0, pu, prot):
    pn = np.empty_like(pn0)
    pv = np.empty_like(pn0)
    _rotate_panels_into(angle, pn0, pu, prot, pn, pv)
    return pn, pv


@numba.njit(cache=True)
def _bounds(q, r, box_lo, box_hi, pc, pu, pv, ph):
    qmin, qmax, rmin, rmax = 1e300, -1e300, 1e300, -1e300
    for b in range(box_lo.shape[0]):
        # extreme projections of a box along q and r: centre ± half-extent
        cq = 0.0
        eq = 0.0
        cr = 0.0
        er = 0.0
        for a in range(3):
            mid = 0.5 * (box_lo[b, a] + box_hi[b, a])
            half = 0.5 * (box_hi[b, a] - box_lo[b, a])
            cq += mid * q[a]
            eq += half * abs(q[a])
            cr += mid * r[a]
            er += half * abs(r[a])
        qmin, qmax = min(qmin, cq - eq), max(qmax, cq + eq)
        rmin, rmax = min(rmin, cr - er), max(rmax, cr + er)
    for j in range(pc.shape[0]):
        cq = pc[j, 0] * q[0] + pc[j, 1] * q[1] + pc[j, 2] * q[2]
        cr = pc[j, 0] * r[0] + pc[j, 1] * r[1] + pc[j, 2] * r[2]
        eq = ph[j, 0] * abs(pu[j, 0] * q[0] + pu[j, 1] * q[1] + pu[j, 2] * q[2]) + ph[j, 1] * abs(
            pv[j, 0] * q[0] + pv[j, 1] * q[1] + pv[j, 2] * q[2]
        )
        er = ph[j, 0] * abs(pu[j, 0] * r[0] + pu[j, 1] * r[1] + pu[j, 2] * r[2]) + ph[j, 1] * abs(
            pv[j, 0] * r[0] + pv[j, 1] * r[1] + pv[j, 2] * r[2]
        )
        qmin, qmax = min(qmin, cq - eq), max(qmax, cq + eq)
        rmin, rmax = min(rmin, cr - er), max(rmax, cr + er)
    return qmin, qmax, rmin, rmax


@numba.njit(cache=True)
def _cast(o0, o1, o2, d, box_lo, box_hi, pc, pn, pu, pv, ph):
    """Largest t such that o + t d lies on a surface (the first surface met by a particle moving along -d).

    Returns (t, kind) with kind -1 for a miss, 0 for a box, 1 + j for panel j.
    """
    best_t = -1e300
    kind = -1
    for b in range(box_lo.shape[0]):
        t0, t1 = -1e300, 1e300
        hit = True
        for a in range(3):
            oa = o0 if a == 0 else (o1 if a == 1 else o2)
            if abs(d[a]) < 1e-15:
                if oa < box_lo[b, a] or oa > box_hi[b, a]:
                    hit = False
                    break
            else:
                ta = (box_lo[b, a] - oa) / d[a]
                tb = (box_hi[b, a] - oa) / d[a]
                if ta > tb:
                    ta, tb = tb, ta
                t0 = max(t0, ta)
                t1 = min(t1, tb)
        if hit and t0 <= t1 and t1 > best_t:
            best_t = t1
            kind = 0
    for j in range(pc.shape[0]):
        dn = d[0] * pn[j, 0] + d[1] * pn[j, 1] + d[2] * pn[j, 2]
        if abs(dn) < 1e-15:
            continue
        t = ((pc[j, 0] - o0) * pn[j, 0] + (pc[j, 1] - o1) * pn[j, 1] + (pc[j, 2] - o2) * pn[j, 2]) / dn
        if t <= best_t:
            continue
        p0 = o0 + t * d[0] - pc[j, 0]
        p1 = o1 + t * d[1] - pc[j, 1]
        p2 = o2 + t * d[2] - pc[j, 2]
        a = p0 * pu[j, 0] + p1 * pu[j, 1] + p2 * pu[j, 2]
        b2 = p0 * pv[j, 0] + p1 * pv[j, 1] + p2 * pv[j, 2]
        if abs(a) <= ph[j, 0] and abs(b2) <= ph[j, 1]:
            best_t = t
            kind = 1 + j
    return best_t, kind


@numba.njit(cache=True)
def _locate_silhouette_kernel(dirs, angles, box_lo, box_hi, pc, pn0, pu, ph, prot, rng):
    n = dirs.shape[0]
    pos = np.empty((n, 3))
    kind_out = np.empty(n, dtype=np.int64)
    q = np.empty(3)
    r = np.empty(3)
    pn = np.empty_like(pn0)
    pv = np.empty_like(pn0)
    for i in range(n):
        d = dirs[i]
        _frame_into(d, q, r)
        _rotate_panels_into(angles[i], pn0, pu, prot, pn, pv)
        qmin, qmax, rmin, rmax = _bounds(q, r, box_lo, box_hi, pc, pu, pv, ph)
        while True:
            a = qmin + (qmax - qmin) * rng.random()
            b = rmin + (rmax - rmin) * rng.random()
            o0, o1, o2 = a * q[0] + b * r[0], a * q[1] + b * r[1], a * q[2] + b * r[2]
            t, k = _cast(o0, o1, o2, d, box_lo, box_hi, pc, pn, pu, pv, ph)
            if k >= 0:
                pos[i, 0] = o0 + t * d[0]
                pos[i, 1] = o1 + t * d[1]
                pos[i, 2] = o2 + t * d[2]
                kind_out[i] = k
                break
    return pos, kind_out


@numba.njit(cache=True)
def _silhouette_area_kernel(dirs, angles, box_lo, box_hi, pc, pn0, pu, ph, prot, n_trials, rng):
    n = dirs.shape[0]
    area = np.empty(n)
    q = np.empty(3)
    r = np.empty(3)
    pn = np.empty_like(pn0)
    pv = np.empty_like(pn0)
    for i in range(n):
        d = dirs[i]
        _frame_into(d, q, r)
        _rotate_panels_into(angles[i], pn0, pu, prot, pn, pv)
        qmin, qmax, rmin, rmax = _bounds(q, r, box_lo, box_hi, pc, pu, pv, ph)
        hits = 0
        for _trial in range(n_trials):
            a = qmin + (qmax - qmin) * rng.random()
            b = rmin + (rmax - rmin) * rng.random()
            _, k = _cast(
                a * q[0] + b * r[0],
                a * q[1] + b * r[1],
                a * q[2] + b * r[2],
                d,
                box_lo,
                box_hi,
                pc,
                pn,
                pu,
                pv,
                ph,
            )
            if k >= 0:
                hits += 1
        area[i] = (qmax - qmin) * (rmax - rmin) * hits / n_trials
    return area


@numba.njit(cache=True)
def _visible_strike_kernel(dirs, angles, box_lo, box_hi, pc, pn0, pu, ph, prot, rng):
    """Face sampling with ray visibility: per direction d, a surface element f facing the flow is drawn with
    probability A_f cos θ_f / S(d), S(d) = Σ_f A_f max(cos θ_f, 0) (boxes: six faces; panels: two-sided,
    |cos θ|), a point uniform on it, and a ray cast from it toward the source. Returns the points, the
    element kind (0 box, 1 + j panel j) and S(d) · 1[nothing lies in front of the point]: an unbiased
    estimate of the visible (unshadowed) projected area A(d), E[S 1_vis] = Σ_f A_f cos θ_f P(vis | f)."""
    n = dirs.shape[0]
    nb = box_lo.shape[0]
    npan = pc.shape[0]
    pos = np.empty((n, 3))
    kind_out = np.empty(n, dtype=np.int64)
    area_out = np.empty(n)
    pn = np.empty_like(pn0)
    pv = np.empty_like(pn0)
    proj = np.empty(6 * nb + npan)
    p = np.empty(3)
    for i in range(n):
        d = dirs[i]
        _rotate_panels_into(angles[i], pn0, pu, prot, pn, pv)
        total = 0.0
        for b in range(nb):
            for a in range(3):
                a1 = (a + 1) % 3
                a2 = (a + 2) % 3
                face = (box_hi[b, a1] - box_lo[b, a1]) * (box_hi[b, a2] - box_lo[b, a2])
                proj[6 * b + 2 * a] = face * max(d[a], 0.0)  # face at box_hi[a], outward normal +e_a
                proj[6 * b + 2 * a + 1] = face * max(-d[a], 0.0)  # face at box_lo[a], normal -e_a
                total += proj[6 * b + 2 * a] + proj[6 * b + 2 * a + 1]
        for j in range(npan):
            dn = d[0] * pn[j, 0] + d[1] * pn[j, 1] + d[2] * pn[j, 2]
            proj[6 * nb + j] = 4.0 * ph[j, 0] * ph[j, 1] * abs(dn)
            total += proj[6 * nb + j]
        if total <= 0.0:
            pos[i, 0], pos[i, 1], pos[i, 2] = 0.0, 0.0, 0.0
            kind_out[i] = -1
            area_out[i] = 0.0
            continue
        u = rng.random() * total
        f = 0
        acc = proj[0]
        while acc < u and f < proj.size - 1:
            f += 1
            acc += proj[f]
        while proj[f] <= 0.0:  # u landed on a boundary: the previous element with area
            f -= 1
        if f < 6 * nb:
            b = f // 6
            a = (f % 6) // 2
            a1 = (a + 1) % 3
            a2 = (a + 2) % 3
            p[a] = box_hi[b, a] if f % 2 == 0 else box_lo[b, a]
            p[a1] = box_lo[b, a1] + (box_hi[b, a1] - box_lo[b, a1]) * rng.random()
            p[a2] = box_lo[b, a2] + (box_hi[b, a2] - box_lo[b, a2]) * rng.random()
            kind = 0
        else:
            j = f - 6 * nb
            s = (2.0 * rng.random() - 1.0) * ph[j, 0]
            t = (2.0 * rng.random() - 1.0) * ph[j, 1]
            for c in range(3):
                p[c] = pc[j, c] + s * pu[j, c] + t * pv[j, c]
            kind = 1 + j
        t_front, _ = _cast(p[0], p[1], p[2], d, box_lo, box_hi, pc, pn, pu, pv, ph)
        scale = 1.0 + abs(p[0]) + abs(p[1]) + abs(p[2])
        pos[i, 0], pos[i, 1], pos[i, 2] = p[0], p[1], p[2]
        kind_out[i] = kind
        area_out[i] = total if t_front <= 1e-9 * scale else 0.0  # something in front: shadowed
    return pos, kind_out, area_out


@numba.njit(cache=True)
def _locate_point_cloud_kernel(dirs, angles, bus_pts, pc, pn0, pu, ph, prot, pan_ab, pan_id, spacing, rng):
    n = dirs.shape[0]
    nb = bus_pts.shape[0]
    na = pan_ab.shape[0]
    npts = nb + na
    pos = np.empty((n, 3))
    kind_out = np.empty(n, dtype=np.int64)
    pts = np.empty((npts, 3))
    pkind = np.empty(npts, dtype=np.int64)
    for k in range(nb):
        pts[k] = bus_pts[k]
        pkind[k] = 0
    for i in range(n):
        d = dirs[i]
        q, r = _frame(d)
        _, pv = _rotated_panels(angles[i], pn0, pu, prot)
        for k in range(na):
            j = pan_id[k]
            pts[nb + k] = pc[j] + pan_ab[k, 0] * pu[j] + pan_ab[k, 1] * pv[j]
            pkind[nb + k] = 1 + j
        pq = np.empty(npts)
        pr = np.empty(npts)
        depth = np.empty(npts)
        for k in range(npts):
            pq[k] = pts[k, 0] * q[0] + pts[k, 1] * q[1] + pts[k, 2] * q[2]
            pr[k] = pts[k, 0] * r[0] + pts[k, 1] * r[1] + pts[k, 2] * r[2]
            depth[k] = pts[k, 0] * d[0] + pts[k, 1] * d[1] + pts[k, 2] * d[2]
        q0 = pq.min()
        r0 = pr.min()
        nq = int((pq.max() - q0) / spacing) + 1
        nr = int((pr.max() - r0) / spacing) + 1
        best = np.full(nq * nr, -1, dtype=np.int64)
        for k in range(npts):
            iq = int((pq[k] - q0) / spacing)
            ir = int((pr[k] - r0) / spacing)
            c = iq * nr + ir
            if best[c] < 0 or depth[k] > depth[best[c]]:
                best[c] = k
        counts = np.zeros(nq, dtype=np.int64)
        for c in range(nq * nr):
            if best[c] >= 0:
                counts[c // nr] += 1
        cdf = np.cumsum(counts)
        u = rng.random() * cdf[-1]
        iq = int(np.searchsorted(cdf, u, side="right"))
        if iq >= nq:
            iq = nq - 1
        pick = int(rng.random() * counts[iq])
        seen = 0
        for ir in range(nr):
            c = iq * nr + ir
            if best[c] >= 0:
                if seen == pick:
                    pos[i] = pts[best[c]]
                    kind_out[i] = pkind[best[c]]
                    break
                seen += 1
    return pos, kind_out


# ----------------------------------------------------------------------------------------------
# Python API
# ----------------------------------------------------------------------------------------------


def _check_dirs(
    directions: NDArray[np.float64], angles: NDArray[np.float64] | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    d = np.ascontiguousarray(directions, dtype=np.float64)
    if d.ndim != 2 or d.shape[1] != 3:
        raise ConfigError("directions must be an (N, 3) array of unit vectors", key="directions")
    d = d / np.linalg.norm(d, axis=1)[:, None]
    a = np.zeros(d.shape[0]) if angles is None else np.ascontiguousarray(angles, dtype=np.float64)
    if a.shape != (d.shape[0],):
        raise ConfigError("one array angle per direction", key="array_angles")
    return d, a


def locate_strikes(
    geometry: Geometry,
    directions: NDArray[np.float64],
    array_angles_rad: NDArray[np.float64] | None = None,
    *,
    method: str = "silhouette",
    grid_spacing_m: float | None = None,
    seed: int = 0,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Strike points R_d/s [m] (body, from the CoM) and whether each is on a solar array.

    Args:
        geometry: from :func:`geometry_from_spacecraft`.
        directions: (N, 3) unit vectors toward where each particle comes from (body axes).
        array_angles_rad: (N,) solar-array rotation angles about their drive axes (default 0).
        method: ``silhouette`` (exact ray-cast) or ``point_cloud`` (thesis rasterisation).
        grid_spacing_m: point-cloud grid spacing (default: 1/6 of the smallest dimension, thesis §5.3.4).
        seed: seed of the kernel's random stream (reproducible).
    """
    d, a = _check_dirs(directions, array_angles_rad)
    g = geometry
    if method == "silhouette":
        pos, kind = _locate_silhouette_kernel(
            d,
            a,
            g.box_lo,
            g.box_hi,
            g.panel_center,
            g.panel_normal,
            g.panel_u,
            g.panel_half,
            g.panel_rotates,
            np.random.default_rng(seed),
        )
    elif method == "point_cloud":
        spacing = grid_spacing_m if grid_spacing_m is not None else g.smallest_dimension_m / 6.0
        if not spacing > 0:
            raise ConfigError("grid spacing must be positive", key="grid_spacing_m")
        bus_pts, pan_ab, pan_id = _point_cloud(g, spacing)
        pos, kind = _locate_point_cloud_kernel(
            d,
            a,
            bus_pts,
            g.panel_center,
            g.panel_normal,
            g.panel_u,
            g.panel_half,
            g.panel_rotates,
            pan_ab,
            pan_id,
            spacing,
            np.random.default_rng(seed),
        )
    else:
        raise ConfigError(
            f"unknown strike-location method {method!r}; use 'silhouette' or 'point_cloud'", key="location"
        )
    on_array = np.zeros(kind.shape, dtype=bool)
    panel_hit = kind >= 1
    on_array[panel_hit] = g.panel_is_array[kind[panel_hit] - 1]
    return pos, on_array


def visible_strikes(
    geometry: Geometry,
    directions: NDArray[np.float64],
    array_angles_rad: NDArray[np.float64] | None = None,
    *,
    seed: int = 0,
) -> tuple[NDArray[np.float64], NDArray[np.bool_], NDArray[np.float64]]:
    """Strike points [m], whether each is on a solar array, and the visible-area weight [m²] per direction.

    Face sampling with ray visibility (:func:`_visible_strike_kernel`): a point is drawn on the surfaces
    facing the flow in proportion to their projected area, and kept with weight S(d) (the total projected
    area of the facing surfaces) when no surface lies in front of it toward the source, 0 when it is
    shadowed. The weight's mean over points is the visible projected area A(d) of direction d, so a flux
    φ(d) over directions gives strikes at the rate Σ φ(d) · weight: direction, point and everything that
    follows (|ΔH|) are weighted by flux × visible area, the exact strike distribution on the spacecraft.
    """
    d, a = _check_dirs(directions, array_angles_rad)
    g = geometry
    pos, kind, area = _visible_strike_kernel(
        d,
        a,
        g.box_lo,
        g.box_hi,
        g.panel_center,
        g.panel_normal,
        g.panel_u,
        g.panel_half,
        g.panel_rotates,
        np.random.default_rng(seed),
    )
    on_array = np.zeros(kind.shape, dtype=bool)
    panel_hit = kind >= 1
    on_array[panel_hit] = g.panel_is_array[kind[panel_hit] - 1]
    return pos, on_array, np.asarray(area, dtype=np.float64)


def _grid_1d(length: float, spacing: float) -> NDArray[np.float64]:
    """Points from 0 to length at a spacing slightly smaller than ``spacing`` (ends included)."""
    n = max(math.ceil(length / (0.7 * spacing)), 1) + 1
    return np.linspace(0.0, length, n)


def _point_cloud(g: Geometry, spacing: float) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Bus face points (body) and panel points as (a, b) coordinates along (u, v) per panel."""
    pts = []
    for lo, hi in zip(g.box_lo, g.box_hi, strict=True):
        size = hi - lo
        for axis in range(3):
            i1, i2 = [k for k in range(3) if k != axis]
            g1 = _grid_1d(size[i1], spacing) + lo[i1]
            g2 = _grid_1d(size[i2], spacing) + lo[i2]
            m1, m2 = np.meshgrid(g1, g2, indexing="ij")
            for face in (lo[axis], hi[axis]):
                p = np.empty((m1.size, 3))
                p[:, axis] = face
                p[:, i1] = m1.ravel()
                p[:, i2] = m2.ravel()
                pts.append(p)
    bus = np.vstack(pts) if pts else np.zeros((0, 3))
    ab, ids = [], []
    for j, half in enumerate(g.panel_half):
        ga = _grid_1d(2 * half[0], spacing) - half[0]
        gb = _grid_1d(2 * half[1], spacing) - half[1]
        ma, mb = np.meshgrid(ga, gb, indexing="ij")
        ab.append(np.column_stack([ma.ravel(), mb.ravel()]))
        ids.append(np.full(ma.size, j, dtype=np.int64))
    pan_ab = np.vstack(ab) if ab else np.zeros((0, 2))
    pan_id = np.concatenate(ids) if ids else np.zeros(0, dtype=np.int64)
    return np.ascontiguousarray(bus), np.ascontiguousarray(pan_ab), pan_id


def silhouette_areas_m2(
    geometry: Geometry,
    directions: NDArray[np.float64],
    array_angles_rad: NDArray[np.float64] | None = None,
    *,
    n_trials: int = 256,
    seed: int = 0,
) -> NDArray[np.float64]:
    """Projected (silhouette) area [m²] seen from each direction, by hit-or-miss Monte Carlo."""
    d, a = _check_dirs(directions, array_angles_rad)
    g = geometry
    return np.asarray(
        _silhouette_area_kernel(
            d,
            a,
            g.box_lo,
            g.box_hi,
            g.panel_center,
            g.panel_normal,
            g.panel_u,
            g.panel_half,
            g.panel_rotates,
            int(n_trials),
            np.random.default_rng(seed),
        )
    )


def mean_silhouette_area_m2(
    geometry: Geometry,
    directions: NDArray[np.float64],
    array_angles_rad: NDArray[np.float64] | None = None,
    *,
    max_directions: int = 4096,
    n_trials: int = 256,
    seed: int = 0,
) -> float:
    """Flux-weighted mean silhouette area [m²]: the average over directions drawn from the flux."""
    d, a = _check_dirs(directions, array_angles_rad)
    k = min(max_directions, d.shape[0])
    return float(np.mean(silhouette_areas_m2(geometry, d[:k], a[:k], n_trials=n_trials, seed=seed)))
