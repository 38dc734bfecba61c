"""Check of the IDS type-007 component order on Jason-1's July 2010 cross-track burns against its element sets.

Every burn of ``ja1man.txt`` from 2010 day 195 to 215 is read token by token (epoch in TAI, duration,
the three ΔV components Q, S, W and the three accelerations, which must equal ΔV / duration component
by component if the order is read right). The argument of latitude ``u`` at each burn comes from SGP4
(the element set before the burn), and a cross-track burn turns the plane by the Gauss equations
(Vallado 2013 §9.3): ``Δi = Δv_W cos u / v`` and ``ΔΩ = Δv_W sin u / (v sin i)``. The per-line and
campaign sums are printed beside the inclination of the element sets before, during and after.

Run: ``python benchmarks/bench_tle_plane_check.py``.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
from sgp4.api import Satrec, jday

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data"
TAI_MINUS_UTC_2010_S = 34.0  # leap seconds in force during 2010 (IERS Bulletin C)
TOKENS_PER_BURN = 15


def read_burns(path: Path, year: int, doy_first: int, doy_last: int) -> list[dict[str, float | dt.datetime]]:
    """Per-burn rows of the IDS lines whose window starts inside the given days."""
    out: list[dict[str, float | dt.datetime]] = []
    for line_no, line in enumerate(path.read_text().splitlines(), 1):
        tok = line.split()
        if len(tok) < 11 or int(tok[1]) != year or not doy_first <= int(tok[2]) <= doy_last:
            continue
        for b in range(int(tok[10])):
            t = tok[11 + TOKENS_PER_BURN * b : 11 + TOKENS_PER_BURN * (b + 1)]
            start = dt.datetime(int(t[0]), 1, 1) + dt.timedelta(days=int(t[1]) - 1, hours=int(t[2]), minutes=int(t[3]))
            when = start + dt.timedelta(seconds=float(t[4]) - TAI_MINUS_UTC_2010_S)
            dur, dv, acc = float(t[5]), [float(x) for x in t[6:9]], [float(x) for x in t[9:12]]
            # accelerations are stated in µm/s²: each must be its own component's ΔV / duration
            worst = max(abs(a * 1e-6 * dur - d) for a, d in zip(acc, dv, strict=True))
            out.append({"line": line_no, "utc": when, "q": dv[0], "s": dv[1], "w": dv[2], "acc_mismatch_mps": worst})
    return out


def main() -> None:
    text = (DATA / "tle" / "Jason-1.tle").read_text().splitlines()
    sats = [Satrec.twoline2rv(text[k], text[k + 1]) for k in range(len(text) - 1) if text[k].startswith("1 ")]
    epochs = np.array([s.jdsatepoch + s.jdsatepochF for s in sats])
    burns = read_burns(DATA / "maneuvers" / "ja1man.txt", 2010, 195, 215)
    per_line: dict[int, list[float]] = {}
    print("burn epoch (UTC)            line  W m/s    S m/s    u deg    Δi deg    ΔΩ deg  |acc·dur−ΔV| m/s")
    for b in burns:
        when = b["utc"]
        assert isinstance(when, dt.datetime)
        jd, fr = jday(when.year, when.month, when.day, when.hour, when.minute, when.second + when.microsecond / 1e6)
        sat = sats[max(0, int(np.searchsorted(epochs, jd + fr)) - 1)]
        _, r_km, v_kms = sat.sgp4(jd, fr)
        r, v = np.asarray(r_km), np.asarray(v_kms)
        h = np.cross(r, v) / np.linalg.norm(np.cross(r, v))
        node = np.cross([0.0, 0.0, 1.0], h)
        node /= np.linalg.norm(node)
        u = float(np.arctan2(np.dot(np.cross(node, r), h), np.dot(node, r)))
        inc, speed = float(np.arccos(h[2])), float(np.linalg.norm(v)) * 1e3
        w = float(b["w"])  # type: ignore[arg-type]
        di, dnode = w * np.cos(u) / speed, w * np.sin(u) / (speed * np.sin(inc))
        acc = per_line.setdefault(int(b["line"]), [0.0, 0.0, 0.0])  # type: ignore[call-overload]
        acc[0] += di
        acc[1] += dnode
        acc[2] += w
        print(
            f"{when:%Y-%m-%d %H:%M:%S}  {b['line']:5d} {w:+7.3f} {float(b['s']):+8.4f} {np.degrees(u):8.1f}"  # type: ignore[arg-type]
            f" {np.degrees(di):+9.4f} {np.degrees(dnode):+9.4f}  {float(b['acc_mismatch_mps']):.1e}"  # type: ignore[arg-type]
        )
    print("per line: summed W (what a component sum states) against the plane rotation the burns make")
    for line_no, (di, dnode, w) in per_line.items():
        speed = 7.2e3
        print(f"  line {line_no}: ΣW {w:+.3f} m/s; Δi {np.degrees(di):+.4f}°, ΔΩ {np.degrees(dnode):+.4f}°; ", end="")
        print(f"implied cross-track ΔV from i {abs(di) * speed:.2f} m/s (v ≈ 7.2 km/s)")
    total_i = sum(x[0] for x in per_line.values())
    print(f"campaign: Δi {np.degrees(total_i):+.4f}°")
    first, last = burns[0]["utc"], burns[-1]["utc"]
    assert isinstance(first, dt.datetime) and isinstance(last, dt.datetime)
    j2000 = dt.datetime(2000, 1, 1, 12)
    lo = (first - j2000).total_seconds() / 86400 + 2451545.0 - 5.0
    hi = (last - j2000).total_seconds() / 86400 + 2451545.0 + 5.0
    print("element sets (inclination, deg) from 5 days before the first burn to 5 days after the last:")
    for k in np.flatnonzero((epochs > lo) & (epochs < hi)):
        stamp = j2000 + dt.timedelta(days=float(epochs[k] - 2451545.0))
        print(f"  {stamp:%Y-%m-%d %H:%M}  i {np.degrees(sats[k].inclo):.4f}")


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_tle_plane_check"):
        main()
