"""Orbit-side evidence for attitude events: the net ΔV a pure torque cannot make.

An external impulse at a surface point r with transferred momentum p changes the angular momentum by
ΔH = r × p and the velocity of the centre of mass by ΔV = p / m. With r within r_max of the centre of
mass, |ΔH| ≤ r_max |p|, so every external impulse that is not a couple moves the orbit by at least

    ΔV_min = |ΔH| / (m r_max)                                                          (1)

(``ev_min_dv_mps`` of :mod:`abrupt.detect.attitude.evidence`, set when the spacecraft file has surfaces).
A thruster leak's force F at r gives τ = r × F and the same bound on its ∫F dt / m. A sensor fault or an
internal event (momentum moved between parts) changes neither the total momentum nor the orbit.

The orbit side (``abrupt detect orbit``: a navigation solution, filtered and tested for impulses) says
whether the orbit moved at the event's time. Its silence is evidence only where it was looking (the
navigation solution covers the time) and only for a ΔV it would have found (its detection floor, the
90 %-detectable |ΔV| in the worst direction that the orbit run reports). So per attitude event:

* ``ev_orbit_dv_mps``: |ΔV| of the orbit event that coincides with it (the largest when several do);
  **0** when the navigation solution covers the event and no orbit event coincides (nothing above the
  floor); **NaN** when no navigation solution covers it (not covered is not "no ΔV");
* ``ev_orbit_dt_s``: the coincident orbit event's time minus the attitude event's [s] (NaN when none);
* ``ev_orbit_dv_floor_mps``: the orbit run's floor at the event (NaN when not covered).

Two events coincide when the gap between their time intervals (each event's time, widened by its
duration where known: the orbit event's ``duration_s`` of a finite burn after its start, the attitude
event's ``ev_duration_s`` either side) is within ``sigmas`` combined σ of the two times
(``time_sigma_s``) plus ``floor_s`` (clock offsets, the orbit solution's sampling).

:func:`apply_orbit_rules` then checks the attitude class against the orbit (after the attitude rules of
:mod:`abrupt.detect.attitude.attribution`; see :class:`OrbitRules`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from abrupt.detect.attitude.attribution import AttributionRules
from abrupt.events import event_ids, event_times_ns
from abrupt.series.timetable import NS

ORBIT_EVIDENCE_COLUMNS = ("ev_orbit_dv_mps", "ev_orbit_dt_s", "ev_orbit_dv_floor_mps")


def _ns(t: object) -> np.datetime64:
    """A time (datetime64, Timestamp or ISO-8601 text; UTC) as datetime64[ns]."""
    ts = pd.Timestamp(str(t))
    if ts.tzinfo is not None:
        ts = ts.tz_convert("UTC").tz_localize(None)
    return np.datetime64(int(ts.value), "ns")


Span = tuple[np.datetime64, np.datetime64]


def merged_spans(spans: Sequence[Span]) -> tuple[tuple[Span, ...], str]:
    """``spans`` (each ending after it starts) as disjoint intervals in time order, and the repair made, counted
    ("" when none): spans out of order are sorted, spans that overlap are merged into one (the navigation
    solution covered their union; spans that only touch, as calibration blocks' do, are joined uncounted)."""
    starts = [int(a.astype(np.int64)) for a, _ in spans]
    unordered = sum(1 for k in range(1, len(starts)) if starts[k] < starts[k - 1])
    out: list[Span] = []
    merged = 0
    for a, b in sorted(spans, key=lambda s: (int(s[0].astype(np.int64)), int(s[1].astype(np.int64)))):
        if out and a <= out[-1][1]:
            merged += int(a < out[-1][1])  # one that only touches the last is no mistake
            out[-1] = (out[-1][0], max(out[-1][1], b))
            continue
        out.append((a, b))
    what = [f"{unordered} out of order, sorted"] if unordered else []
    what += [f"{merged} overlapping an earlier one, merged"] if merged else []
    repairs = f"navigation spans: {'; '.join(what)} ({len(spans)} given, {len(out)} left)" if what else ""
    return tuple(out), repairs


@dataclass(frozen=True)
class NavigationCoverage:
    """Where a navigation solution was searched for impulses, and the smallest ΔV it would have found.

    ``spans_utc``: (start, end) pairs of the intervals the orbit run tested (UTC); ``dv_floor_mps``: the
    orbit run's detection floor [m/s] (its 90 %-detectable |ΔV| in the worst direction, or a value the user gives);
    ``edge_s``: a margin at each end of each span that does not count as covered [s] (the filters have
    seen little data there); ``source``: where the floor and the spans came from (for the reasons).
    Spans that do not end after they start are a ValueError naming the span; spans out of order or
    overlapping are sorted and merged (:func:`merged_spans`), the repair counted in ``repairs``.
    """

    spans_utc: tuple[tuple[np.datetime64, np.datetime64], ...]
    dv_floor_mps: float
    edge_s: float = 0.0
    source: str = ""
    repairs: str = field(default="", init=False, compare=False)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dv_floor_mps) and self.dv_floor_mps > 0):
            raise ValueError(f"the orbit ΔV floor must be a positive number of m/s, got {self.dv_floor_mps}")
        if not (math.isfinite(self.edge_s) and self.edge_s >= 0):
            raise ValueError(f"the edge margin must be ≥ 0 s, got {self.edge_s}")
        spans = tuple((_ns(a), _ns(b)) for a, b in self.spans_utc)
        for k, (a, b) in enumerate(spans):
            if not b > a:
                raise ValueError(f"navigation span {k + 1} ({a}..{b}) does not end after it starts")
        merged, repairs = merged_spans(spans)
        object.__setattr__(self, "spans_utc", merged)
        object.__setattr__(self, "repairs", repairs)

    def covers(self, t_ns: np.ndarray) -> np.ndarray:
        """Whether each time [ns since the epoch] is inside a span, ``edge_s`` away from its ends."""
        t = np.asarray(t_ns, dtype=np.int64)
        out = np.zeros(t.shape, dtype=bool)
        edge = int(self.edge_s * NS)
        for a, b in self.spans_utc:
            lo, hi = int(a.astype(np.int64)) + edge, int(b.astype(np.int64)) - edge
            out |= (t >= lo) & (t <= hi)
        return out


@dataclass(frozen=True)
class OrbitMatch:
    """When an orbit event coincides with an attitude event: a gap within ``sigmas`` combined σ of the two
    times plus ``floor_s`` [s]."""

    sigmas: float = 3.0
    floor_s: float = 30.0


def _column(frame: pd.DataFrame, name: str) -> np.ndarray:
    if name not in frame.columns:
        return np.full(len(frame), np.nan)
    return np.asarray(pd.to_numeric(frame[name], errors="coerce"), dtype=float)


def orbit_dv_mps(orbit_events: pd.DataFrame) -> np.ndarray:
    """|ΔV| of each orbit event [m/s]: ``dv_mps``, or the norm of its orbit-frame components."""
    dv = _column(orbit_events, "dv_mps")
    comp = np.column_stack([_column(orbit_events, c) for c in ("dv_r_mps", "dv_t_mps", "dv_n_mps")])
    norm = np.sqrt(np.sum(comp**2, axis=1)) if len(orbit_events) else np.zeros(0)
    return np.where(np.isfinite(dv), dv, norm)


def orbit_evidence(
    attitude_events: pd.DataFrame,
    orbit_events: pd.DataFrame,
    coverage: NavigationCoverage,
    match: OrbitMatch | None = None,
) -> pd.DataFrame:
    """``attitude_events`` with the columns of :data:`ORBIT_EVIDENCE_COLUMNS` (module docstring).

    ``orbit_events``: the orbit run's events of the same spacecraft (the event schema: ``time_utc``,
    ``time_sigma_s`` [s], ``dv_mps`` or ``dv_r/t/n_mps`` [m/s]; ``duration_s`` [s] of a finite burn if
    given). An orbit event without a finite ΔV cannot coincide with anything.
    """
    m = match or OrbitMatch()
    out = attitude_events.copy()
    n = len(out)
    dv_out = np.full(n, np.nan)
    dt_out = np.full(n, np.nan)
    floor_out = np.full(n, np.nan)
    if n:
        t_a = event_times_ns(out)
        sig_a = np.nan_to_num(_column(out, "time_sigma_s"), nan=0.0)
        dur_a = np.nan_to_num(np.clip(_column(out, "ev_duration_s"), 0.0, None), nan=0.0)
        t_o = event_times_ns(orbit_events)
        sig_o = np.nan_to_num(_column(orbit_events, "time_sigma_s"), nan=0.0)
        dur_o = np.nan_to_num(np.clip(_column(orbit_events, "duration_s"), 0.0, None), nan=0.0)
        dv_o = orbit_dv_mps(orbit_events)
        covered = coverage.covers(t_a)
        for i in range(n):
            if not covered[i]:
                continue
            floor_out[i] = coverage.dv_floor_mps
            # Gap between [t_a − D_a, t_a + D_a] and [t_o, t_o + D_o] [s]; 0 when they overlap.
            lo_a, hi_a = (t_a[i] - t_o) / NS - dur_a[i], (t_a[i] - t_o) / NS + dur_a[i]
            gap = np.maximum(0.0, np.maximum(lo_a - dur_o, -hi_a))
            tol = m.sigmas * np.hypot(sig_a[i], sig_o) + m.floor_s
            near = np.flatnonzero((gap <= tol) & np.isfinite(dv_o))
            if near.size == 0:
                dv_out[i] = 0.0
                continue
            k = int(near[np.argmax(dv_o[near])])
            dv_out[i] = float(dv_o[k])
            dt_out[i] = float((t_o[k] - t_a[i]) / NS)
    out["ev_orbit_dv_mps"] = dv_out
    out["ev_orbit_dt_s"] = dt_out
    out["ev_orbit_dv_floor_mps"] = floor_out
    return out


@dataclass(frozen=True)
class OrbitRules:
    """Limits of the orbit-side rules (ratios to the orbit run's ΔV floor; no fitted value).

    ``decisive``: a ΔV at least this many floors is one the orbit run would have found (its floor is a
    90 %-detectable |ΔV| in the worst direction; three of them leave no real chance of a miss), and an
    orbit ΔV this many floors above is no noise of the orbit solution. Between one and ``decisive``
    floors the physics is not decisive: the confidence is lowered, the class kept. ``body_sigma`` and
    ``takeup_min``: when the attitude evidence shows a torque (the body moved beyond ``body_sigma`` σ of
    its noise and the wheels took up at least ``takeup_min`` of the step), as in
    :class:`~abrupt.detect.attitude.attribution.AttributionRules`.
    """

    decisive: float = 3.0
    body_sigma: float = AttributionRules().body_sigma
    takeup_min: float = AttributionRules().takeup_min


def _lowered(confidence: float) -> float:
    """Half the confidence's excess over 0.5 (the floor of the attribution's confidence scale)."""
    return 0.5 + 0.5 * max(0.0, confidence - 0.5)


def _mm(x: float) -> str:
    return f"{1e3 * x:.3g} mm/s"


def _val(row: pd.Series, name: str) -> float:
    v = row.get(name, np.nan)
    try:
        return float(v)
    except (TypeError, ValueError):
        return float("nan")


def orbit_rule(
    kind: str,
    confidence: float,
    reason: str,
    row: pd.Series,
    rules: OrbitRules | None = None,
    mass_kg: float = math.nan,
) -> tuple[str, float, str]:
    """The class, confidence and reason of one event once the orbit side is heard (:func:`apply_orbit_rules`)."""
    r = rules or OrbitRules()
    dv, floor = _val(row, "ev_orbit_dv_mps"), _val(row, "ev_orbit_dv_floor_mps")
    if not (math.isfinite(dv) and math.isfinite(floor)):
        return kind, confidence, reason  # no navigation solution at this time: nothing to say
    dv_min, dt = _val(row, "ev_min_dv_mps"), _val(row, "ev_orbit_dt_s")
    seen = dv > 0.0
    at = f" at {dt:+.0f} s" if math.isfinite(dt) else ""
    if kind == "strike":
        if not seen and math.isfinite(dv_min) and dv_min >= r.decisive * floor:
            return (
                "unknown",
                0.5,
                (
                    f"{reason}; but a strike here must have moved the orbit by ≥ {_mm(dv_min)} and the navigation "
                    f"solution shows nothing above {_mm(floor)}: not a strike"
                ),
            )
        if not seen and math.isfinite(dv_min) and dv_min >= floor:
            return (
                kind,
                _lowered(confidence),
                (
                    f"{reason}; a strike here must have moved the orbit by ≥ {_mm(dv_min)}, the navigation solution "
                    f"shows nothing above {_mm(floor)} (not decisive below {r.decisive:g} floors: confidence lowered)"
                ),
            )
        if seen and math.isfinite(dv_min) and dv < dv_min / r.decisive:
            return (
                kind,
                _lowered(confidence),
                (
                    f"{reason}; coincident orbit ΔV {_mm(dv)}{at} is below the {_mm(dv_min)} a strike here must cause "
                    "(confidence lowered)"
                ),
            )
        if seen:
            return kind, confidence, f"{reason}; coincident orbit ΔV {_mm(dv)}{at} (a net force, as a strike makes)"
        return kind, confidence, reason
    if kind in ("sensor_fault", "internal") and seen:
        what = "a one-channel fault" if kind == "sensor_fault" else "momentum moved between parts"
        if dv < r.decisive * floor:
            return (
                kind,
                _lowered(confidence),
                (
                    f"{reason}; coincident orbit ΔV {_mm(dv)}{at}, near the floor {_mm(floor)} "
                    f"({what} moves no orbit: confidence lowered)"
                ),
            )
        body, body_sig = _val(row, "ev_body_share"), _val(row, "ev_body_share_sigma")
        takeup = _val(row, "ev_wheel_takeup")
        torque = (
            math.isfinite(body) and math.isfinite(body_sig) and body >= r.body_sigma * body_sig
            and math.isfinite(takeup) and takeup >= r.takeup_min
        )  # fmt: skip
        new = "external_non_strike" if torque else "unknown"
        return (
            new,
            0.5,
            (
                f"was {kind} ({reason}); but a coincident orbit ΔV of {_mm(dv)}{at} (floor {_mm(floor)}) is a net "
                f"force, which {what} cannot make" + ("; the body and the wheels saw a torque" if torque else "")
            ),
        )
    if kind == "external_non_strike":
        if seen:
            dh = _val(row, "dH_Nms")
            arm = dh / (mass_kg * dv) if math.isfinite(dh) and math.isfinite(mass_kg) and mass_kg > 0 else math.nan
            lever = f": lever arm |ΔH|/(m ΔV) = {arm:.3g} m" if math.isfinite(arm) else ""
            return kind, confidence, f"{reason}; net force: coincident orbit ΔV {_mm(dv)}{at} (a leak's r × F{lever})"
        if math.isfinite(dv_min) and dv_min >= r.decisive * floor:
            return (
                kind,
                confidence,
                (
                    f"{reason}; no orbit ΔV above {_mm(floor)} where a single force would give ≥ {_mm(dv_min)}: a pure "
                    "torque (a couple, a magnetic dump), not one thruster"
                ),
            )
    return kind, confidence, reason


def apply_orbit_rules(events: pd.DataFrame, rules: OrbitRules | None = None, mass_kg: float = math.nan) -> pd.DataFrame:
    """``events`` (with :func:`orbit_evidence`'s columns and the attribution's ``kind``, ``kind_confidence``,
    ``kind_reason``) with each class checked against the orbit side; ``event_id`` recomputed (it holds the kind).

    (a) A ``strike`` whose least ΔV (1) is at least ``decisive`` floors while the navigation solution covering
    it shows no ΔV is not a strike: ``unknown``. Between one and ``decisive`` floors, or with a coincident ΔV
    well below the least ΔV: the confidence is lowered. (b) A ``sensor_fault`` or ``internal`` event with a
    coincident orbit ΔV of at least ``decisive`` floors contradicts itself: ``external_non_strike`` when the
    body and the wheels saw a torque, else ``unknown``; nearer the floor, the confidence is lowered. (c) An
    ``external_non_strike`` event with a coincident ΔV says so in its reason, with the lever arm
    |ΔH| / (m ΔV) when ``mass_kg`` is given; without one where a single force would have been seen, the
    reason says it was a pure torque. ``mass_kg``: the spacecraft's mass [kg].
    """
    out = events.copy()
    if not len(out) or "ev_orbit_dv_mps" not in out.columns:
        return out
    kinds, confs, reasons = [], [], []
    for _, row in out.iterrows():
        conf = _val(row, "kind_confidence")
        reason = "" if pd.isna(row.get("kind_reason", "")) else str(row.get("kind_reason", ""))
        k, c, why = orbit_rule(str(row["kind"]), conf if math.isfinite(conf) else 0.5, reason, row, rules, mass_kg)
        kinds.append(k)
        confs.append(c)
        reasons.append(why)
    out["kind"] = pd.Series(kinds, index=out.index).astype(events["kind"].dtype)
    out["kind_confidence"] = confs
    out["kind_reason"] = pd.Series(reasons, index=out.index, dtype="string")
    out["event_id"] = event_ids(out)
    return out


def spans_from_text(texts: Sequence[str | tuple[object, object]]) -> tuple[Span, ...]:
    """Spans ``START..END`` (ISO-8601 UTC, a trailing ``Z`` allowed), or (start, end) pairs of times, as
    datetime64 pairs; ValueError names the span that is not one."""
    spans = []
    for k, text in enumerate(texts):
        if isinstance(text, str):
            parts: Sequence[object] = text.split("..")
            if len(parts) != 2:
                raise ValueError(f"navigation span {text!r} is not START..END")
        else:
            parts = tuple(text)
            if len(parts) != 2:
                raise ValueError(f"navigation span {k + 1} ({text!r}) is not a (start, end) pair")
        try:
            a, b = (_ns(str(p).strip().rstrip("Z")) for p in parts)
        except ValueError:
            raise ValueError(f"navigation span {text!r}: a time is not ISO-8601") from None
        spans.append((a, b))
    return tuple(spans)
