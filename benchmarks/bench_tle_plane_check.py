"""Check of the IDS type-007 component order on Jason-1's July 2010 cross-track burns against its element sets.

Every burn of ``ja1man.txt`` from 2010 day 195 to 215 is read token by token (epoch in TAI, duration,
the three ΔV components Q, S, W and the three accelerations, which must equal ΔV / duration component
by component if the order is read right). The argument of latitude ``u`` at each burn comes from SGP4
(the element set before the burn), and a cross-track burn turns the plane by the Gauss equations
(Vallado 2013 §9.3): ``Δi = Δv_W cos u / v`` and ``ΔΩ = Δv_W sin u / (v sin i)``. The per-line and
campaign sums are printed beside the inclination of the element sets before, during and after.

``--lines``: every line with cross-track burns on the four shared LEO histories: the operator's plane
rotation (burns summed as vectors at their own u, so opposite burns half an orbit apart add), the sets'
change of (i, sin i · ΔΩ residual) from the 20 days before (linear drift removed) to 4-10 days after,
the cross-track ΔV the sets imply along the operator's direction and from i and the node separately
(:func:`abrupt.detect.tle.plane.implied_cross_track_dv` at the burns' effective u; NaN where its lever
is below 0.2), the share of it across the burn's
own gap (1: a sharp step; small: a ramp over the sets' fit spans) and the normal step noise in m/s;
then per run of lines (each within 7 days of the previous) the net operator rotation, its largest
running sum, and the sets' change across the whole run.

Run: ``python benchmarks/bench_tle_plane_check.py [--lines]``.
"""

from __future__ import annotations

import datetime as dt
from pathlib import Path

import numpy as np
import pandas as pd
from sgp4.api import Satrec, jday

from abrupt.detect.tle.elements import mean_element_series
from abrupt.detect.tle.plane import implied_cross_track_dv
from abrupt.readers.tle import read_tle

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "data"
TAI_MINUS_UTC_2010_S = 34.0  # leap seconds in force during 2010 (IERS Bulletin C)
SATS = {"Jason-1": "ja1man.txt", "Jason-3": "ja3man.txt", "Sentinel-3A": "s3aman.txt", "CryoSat-2": "cs2man.txt"}
MIN_W_MPS = 0.02
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


LEAP_STEPS_UTC = (  # (first day, TAI − UTC in s) from IERS Bulletin C, 1999-2022
    (dt.datetime(1999, 1, 1), 32.0),
    (dt.datetime(2006, 1, 1), 33.0),
    (dt.datetime(2009, 1, 1), 34.0),
    (dt.datetime(2012, 7, 1), 35.0),
    (dt.datetime(2015, 7, 1), 36.0),
    (dt.datetime(2017, 1, 1), 37.0),
)


def tai_minus_utc_s(when: dt.datetime) -> float:
    """TAI − UTC (s) in force at ``when`` (1999-2022)."""
    return [v for start, v in LEAP_STEPS_UTC if when >= start][-1]


def argument_of_latitude(sat: Satrec, when: dt.datetime) -> tuple[float, float, float]:
    """u (rad), i (rad) and speed (m/s) of the SGP4 state of ``sat`` at ``when`` (TEME)."""
    jd, fr = jday(when.year, when.month, when.day, when.hour, when.minute, when.second + when.microsecond / 1e6)
    _, r_km, v_kms = sat.sgp4(jd, fr)
    r, v = np.asarray(r_km), np.asarray(v_kms)
    h = np.cross(r, v) / np.linalg.norm(np.cross(r, v))
    node = np.cross([0.0, 0.0, 1.0], h)
    node /= np.linalg.norm(node)
    u = float(np.arctan2(np.dot(np.cross(node, r), h), np.dot(node, r)))
    return u, float(np.arccos(h[2])), float(np.linalg.norm(v)) * 1e3


def line_rotations(sat_name: str) -> pd.DataFrame:
    """Per IDS line with cross-track burns: the plane rotation its burns make (Gauss equations at each
    burn's u, summed as vectors) against the element sets' change of (i, sin i · ΔΩ residual)."""
    text = (DATA / "tle" / f"{sat_name}.tle").read_text().splitlines()
    sats = [Satrec.twoline2rv(text[k], text[k + 1]) for k in range(len(text) - 1) if text[k].startswith("1 ")]
    jd_sets = np.array([s.jdsatepoch + s.jdsatepochF for s in sats])
    history = read_tle(DATA / "tle" / f"{sat_name}.tle")
    series = mean_element_series(history, "leo")
    t_set = pd.DatetimeIndex(history.elements["epoch_utc"]).tz_localize(None)
    normal = np.column_stack([series["i_rad"], series["raan_resid_sin_i_rad"]])
    step = np.diff(normal, axis=0)
    noise = 1.4826 * np.median(np.abs(step - np.median(step, axis=0)), axis=0)
    rows = []
    for line_no, line in enumerate((DATA / "maneuvers" / SATS[sat_name]).read_text().splitlines(), 1):
        tok = line.split()
        if len(tok) < 11:
            continue
        rot, dv_w, first = np.zeros(2), 0.0, None
        for b in range(int(tok[10])):
            t = tok[11 + TOKENS_PER_BURN * b : 11 + TOKENS_PER_BURN * (b + 1)]
            tai = dt.datetime(int(t[0]), 1, 1) + dt.timedelta(days=int(t[1]) - 1, hours=int(t[2]), minutes=int(t[3]))
            when = tai + dt.timedelta(seconds=float(t[4]) - tai_minus_utc_s(tai))
            first = first or when
            w = float(t[8])
            if w == 0.0:
                continue
            jd = (when - dt.datetime(2000, 1, 1, 12)).total_seconds() / 86400 + 2451545.0
            u, _, speed = argument_of_latitude(sats[max(0, int(np.searchsorted(jd_sets, jd)) - 1)], when)
            rot += (w / speed) * np.array([np.cos(u), np.sin(u)])  # (Δi, sin i ΔΩ), Vallado 2013 §9.3
            dv_w += abs(w)
        if dv_w < MIN_W_MPS or first is None:
            continue
        before = np.flatnonzero((t_set < first) & (t_set >= first - pd.Timedelta(days=20)))
        after = np.flatnonzero((t_set > first + pd.Timedelta(days=4)) & (t_set <= first + pd.Timedelta(days=10)))
        if before.size < 5 or after.size < 2:
            continue
        days = (t_set - first).total_seconds().to_numpy() / 86400.0
        fit = [np.polyfit(days[before], normal[before, c], 1) for c in (0, 1)]
        wide = np.array([np.median(normal[after, c] - np.polyval(fit[c], days[after])) for c in (0, 1)])
        k0 = before[-1]
        sharp = normal[k0 + 1] - normal[k0] - np.array([fit[c][0] for c in (0, 1)]) * (days[k0 + 1] - days[k0])
        unit = rot / np.linalg.norm(rot) if np.linalg.norm(rot) > 0 else np.zeros(2)
        # the burns' effective u (the direction of their summed rotation): each element's own estimate
        u_eff = float(np.arctan2(rot[1], rot[0]))
        from_i, from_node = implied_cross_track_dv(wide[0], wide[1], u_eff, speed)
        rows.append(
            {
                "line": line_no,
                "first_burn_utc": f"{first:%Y-%m-%d %H:%M}",
                "sum_abs_w_mps": dv_w,
                "dv_plane_op_mps": speed * float(np.linalg.norm(rot)),
                "di_op_mdeg": 1e3 * np.degrees(rot[0]),
                "sin_i_dnode_op_mdeg": 1e3 * np.degrees(rot[1]),
                "di_sets_mdeg": 1e3 * np.degrees(wide[0]),
                "sin_i_dnode_sets_mdeg": 1e3 * np.degrees(wide[1]),
                "dv_plane_sets_mps": speed * float(np.dot(wide, unit)),
                "u_eff_deg": float(np.degrees(u_eff)),
                "dv_from_i_mps": float(from_i),
                "dv_from_node_mps": float(from_node),
                "first_gap_share": float(np.dot(sharp, unit) / np.dot(wide, unit)) if np.dot(wide, unit) else np.nan,
                "step_noise_mps": speed * float(np.hypot(*noise)),
            }
        )
    return pd.DataFrame(rows)


def runs_table(sat_name: str, table: pd.DataFrame, chain_days: float = 7.0) -> pd.DataFrame:
    """Lines chained within ``chain_days`` form a run: its net operator rotation (the lines' vectors summed)
    against the sets' change from the 20 days before its first line to 4-10 days after its last."""
    history = read_tle(DATA / "tle" / f"{sat_name}.tle")
    series = mean_element_series(history, "leo")
    t_set = pd.DatetimeIndex(history.elements["epoch_utc"]).tz_localize(None)
    normal = np.column_stack([series["i_rad"], series["raan_resid_sin_i_rad"]])
    starts = pd.to_datetime(table["first_burn_utc"])
    run_id = np.concatenate(([0], np.cumsum(np.diff(starts.to_numpy()) > np.timedelta64(int(chain_days * 86400), "s"))))
    rows = []
    for rid in np.unique(run_id):
        sub, first = table.loc[run_id == rid], starts[run_id == rid].iloc[0]
        last = starts[run_id == rid].iloc[-1]
        days = (t_set - first).total_seconds().to_numpy() / 86400.0
        span = (last - first).total_seconds() / 86400.0
        before = np.flatnonzero((days < 0) & (days >= -20))
        after = np.flatnonzero((days > span + 4) & (days <= span + 10))
        if before.size < 5 or after.size < 2:
            continue
        fit = [np.polyfit(days[before], normal[before, c], 1) for c in (0, 1)]
        sets = 1e3 * np.degrees([np.median(normal[after, c] - np.polyval(fit[c], days[after])) for c in (0, 1)])
        op = np.array([sub["di_op_mdeg"].sum(), sub["sin_i_dnode_op_mdeg"].sum()])
        peak = np.abs(np.cumsum(sub["di_op_mdeg"].to_numpy())).max()
        rows.append(
            {
                "first_line_utc": f"{first:%Y-%m-%d}",
                "lines": len(sub),
                "days": span,
                "largest_line_mdeg": float(np.abs(sub["di_op_mdeg"]).max()),
                "largest_running_sum_mdeg": float(peak),
                "net_di_op_mdeg": float(op[0]),
                "net_sin_i_dnode_op_mdeg": float(op[1]),
                "di_sets_mdeg": float(sets[0]),
                "sin_i_dnode_sets_mdeg": float(sets[1]),
            }
        )
    return pd.DataFrame(rows)


def lines_table() -> None:
    """Every shared LEO history's cross-track lines and runs of lines (module docstring)."""
    for sat_name in SATS:
        table = line_rotations(sat_name)
        print(f"\n{sat_name}: {len(table)} lines with Σ|W| >= {MIN_W_MPS} m/s")
        if table.empty:
            continue
        with pd.option_context("display.width", 250, "display.max_columns", 20):
            print(table.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
        ratio = table["dv_plane_sets_mps"] / table["dv_plane_op_mps"]
        ok = table["dv_plane_op_mps"] > 0
        print(
            f"  median sets/operator plane ΔV {np.nanmedian(ratio[ok]):.2f} (from i alone "
            f"{np.nanmedian(table['dv_from_i_mps'] / table['dv_plane_op_mps']):.2f}, from the node alone "
            f"{np.nanmedian(table['dv_from_node_mps'] / table['dv_plane_op_mps']):.2f}); median share of the change "
            f"across the burn's own gap {np.nanmedian(table['first_gap_share']):.2f}; lines whose burns net out in "
            f"plane (rotation < 10 % of Σ|W|): {int((table['dv_plane_op_mps'] < 0.1 * table['sum_abs_w_mps']).sum())}"
        )
        print("  runs of lines (each within 7 days of the previous): net operator rotation against the sets")
        print(runs_table(sat_name, table).to_string(index=False, float_format=lambda v: f"{v:.2f}"))


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
        u, inc, speed = argument_of_latitude(sats[max(0, int(np.searchsorted(epochs, jd + fr)) - 1)], when)
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
    import sys

    from _results import variant, write_results

    with write_results("bench_tle_plane_check", variant({"--lines": "lines"})):
        lines_table() if "--lines" in sys.argv[1:] else main()
