"""Attribution of the flight pipeline's events: evidence columns and the physical class in ``kind``.

:func:`abrupt.pipelines.flight.process_span` computes the evidence of every peak
(:func:`abrupt.detect.attitude.evidence.event_evidence`) while it still holds the chunk's telemetry;
this module joins it to the events above the threshold, classifies each
(:func:`abrupt.detect.attitude.attribution.classify`) and writes ``kind`` (``strike``,
``sensor_fault``, ``external_non_strike``, ``internal`` or ``unknown``), ``kind_confidence``,
``kind_channel`` (the faulty channel of a sensor fault), ``kind_reason`` and the ``ev_*`` columns.
The event identifier includes the kind, so it is recomputed.

:func:`rescan_after_faults` looks again where a sensor fault made an event: the faulty channel is
corrected from the other sensors (:mod:`abrupt.detect.attitude.repair`), ᴺH recomputed, and the step
statistic rescanned around the event, so that a strike within a minute of the fault (which the
fault's event covered: peaks are one window span apart) is found and classified as its own event.
Around an external torque's event (a leak, a venting sequence: one body direction) nothing can be
repaired, since the torque is real; the ramp's body direction is taken out of ᴺH instead
(:mod:`abrupt.detect.attitude.ramp_step`) and the rest rescanned: a peak there is kept only when its
evidence says strike (an impulsive step off the torque's direction), not another piece of the torque.
Around a strike whose window also holds a ramp (a leak beside it: one event, at the larger step), the
strike's fitted step is taken out and the rest rescanned: a peak there is kept when its evidence is an
external torque's, so the leak gets an event of its own. No rescan looks at a step the detector already
has, and a step found by several rescans is one new peak (:func:`merge_found`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields, replace

import numpy as np
import pandas as pd

from abrupt.detect.attitude.attribution import (
    DUMP_REASON,
    Attribution,
    AttributionRules,
    classify,
    compare_hypotheses,
)
from abrupt.detect.attitude.evidence import EventEvidence, event_evidence, profile_fits, profile_key
from abrupt.detect.attitude.flight_glr import FlightGlrDetector, Peak
from abrupt.detect.attitude.ramp_step import (
    RampStep,
    WindowFits,
    body_frame_momentum,
    fit_ramp_step,
    from_body_increments,
)
from abrupt.detect.attitude.repair import repair_sensor_fault
from abrupt.detect.attitude.steps import best_step_beside, local_steps
from abrupt.events import event_ids, format_time_utc
from abrupt.model.rotations import dcm_from_quaternion
from abrupt.model.spacecraft import Spacecraft
from abrupt.series.timetable import NS, Timetable
from abrupt.series.timetable_momentum import timetable_momentum
from abrupt.types import BoolArray, FloatArray

ATTRIBUTION_COLUMNS = ("kind_confidence", "kind_channel", "kind_reason")


def attribute_events(
    events: pd.DataFrame, evidence: Mapping[int, EventEvidence], rules: AttributionRules | None = None
) -> pd.DataFrame:
    """``events`` with ``kind`` from the rules and the evidence columns (events without evidence: unknown)."""
    if not len(events):
        out = events.copy()
        for c in (*ATTRIBUTION_COLUMNS, *EventEvidence().as_dict()):
            out[c] = pd.Series(dtype="string" if c in ("kind_channel", "kind_reason") else "float64")
        return out
    by_time = {format_time_utc(np.datetime64(t, "ns")): e for t, e in evidence.items()}
    rows = []
    for t in events["time_utc"].astype(str):
        ev = by_time.get(t, EventEvidence())
        a = classify(ev, rules)
        rows.append(
            {
                "kind": a.kind,
                "kind_confidence": a.confidence,
                "kind_channel": a.channel,
                "kind_reason": a.reason,
                **ev.as_dict(),
            }
        )
    extra = pd.DataFrame(rows, index=events.index)
    out = events.copy()
    out["kind"] = extra.pop("kind").astype(out["kind"].dtype)
    for c in extra.columns:
        out[c] = extra[c].astype("string") if c in ("kind_channel", "kind_reason") else extra[c]
    out["event_id"] = event_ids(out)
    return out


#: Where a second event is looked for around a sensor fault's event [s] (half a window span either side:
#: a fault that lasts has two edges, and the event may sit on either), and how far from the fault's own
#: step it must be [s] (nearer, the two cannot be told apart).
RESCAN_SPAN_S = (-300.0, 300.0)
RESCAN_APART_S = 10.0
#: How far beyond its noise the ramp fit around an external torque's event (the evidence's window,
#: :func:`~abrupt.detect.attitude.evidence.profile_fits`) must be to have a direction [σ].
RAMP_SIGMA_MIN = 5.0
#: The running median [s] that takes a torque's signal out along its body direction (a venting pulse train's
#: steps 5-60 s apart, a leak's ramp: each followed; the white noise left).
TORQUE_MEDIAN_S = 61.0


def _rows(table: Timetable, a: int, b: int) -> Timetable:
    """Rows [a, b) of ``table`` (every per-sample array sliced)."""
    per_row = {f.name for f in fields(Timetable)} - {"channel_valid", "missing_channels"}
    sub = {k: getattr(table, k)[a:b] for k in per_row}
    return replace(table, **sub, channel_valid={k: v[a:b] for k, v in table.channel_valid.items()})


def _best_peak(
    detector: FlightGlrDetector,
    hc_sub: FloatArray,
    ok_sub: BoolArray,
    g_sub: np.ndarray,
    dt: float,
    t0_ns: int,
    floor: float,
    keep_sub: BoolArray | None,
    span_ns: tuple[int, int] | None = None,
    avoid: tuple[tuple[int, float, float], ...] = (),
    located: bool = True,
) -> tuple[int, Peak] | None:
    """The strongest peak of the statistic of ``hc_sub`` above ``floor`` within ``span_ns`` (default
    ``RESCAN_SPAN_S`` around ``t0_ns``), more than ``RESCAN_APART_S`` from ``t0_ns`` and outside each
    (time [ns], before [s], after [s]) of ``avoid``, both the statistic's peak and (when ``located``) the
    step located near it (None when there is none)."""
    win = detector.windows(dt)
    stat = detector.statistic(hc_sub, ok_sub, win)
    lo, hi = span_ns or (t0_ns + int(RESCAN_SPAN_S[0] * NS), t0_ns + int(RESCAN_SPAN_S[1] * NS))
    zones = ((t0_ns, RESCAN_APART_S, RESCAN_APART_S), *avoid)

    def free(t: np.ndarray) -> np.ndarray:
        ok_t = (t >= lo) & (t <= hi)
        for tz, before, after in zones:
            ok_t &= ~((t >= tz - int(before * NS)) & (t <= tz + int(after * NS)))
        return ok_t

    look = free(g_sub)
    if keep_sub is not None:
        look &= keep_sub
    stat = np.where(look, stat, np.nan)
    cands = [
        (j, p)
        for j, p in detector.find_peaks(hc_sub, ok_sub, stat, g_sub, dt, win)
        if p.value > floor and (not located or free(np.array([p.time_ns]))[0])
    ]
    return max(cands, key=lambda c: c[1].value) if cands else None


def _window_fits(table: Timetable, cleaned_H_N: FloatArray, i0: int, fits: WindowFits | None) -> WindowFits:
    """The ramp window's fits around row ``i0`` (the evidence's, :func:`profile_fits`): ``fits`` (the
    event's evidence fits) when they are of this window, else new ones."""
    t0 = int(table.time_ns[i0])
    if fits is not None and fits.key == profile_key(table, t0):
        return fits
    return profile_fits(table, cleaned_H_N, t0)


def _to_inertial(h_N: FloatArray, y_B: FloatArray, q_BN: FloatArray) -> FloatArray:
    """Body-frame momentum ``y_B`` (changed from that of ``h_N``) back in inertial axes, anchored at the
    first finite row of ``h_N``; rows where ``h_N`` is not finite stay NaN."""
    first = int(np.argmax(np.isfinite(h_N).all(axis=1)))
    h0 = np.where(np.isfinite(h_N[first]), h_N[first], 0.0)
    return np.where(np.isfinite(h_N), from_body_increments(y_B, q_BN, h0), np.nan)


def _off_ramp(
    table: Timetable, cleaned_H_N: FloatArray, i0: int, a: int, b: int, fits: WindowFits | None = None
) -> FloatArray | None:
    """Cleaned ᴺH over rows [a, b) with the signal along the body direction of the ramp or sequence around
    row ``i0`` removed (its running median over ``TORQUE_MEDIAN_S``; the noise along it stays), or None
    when the window needs no ramp. A leak or a venting sequence keeps
    one body direction; what steps off it is a second source. The direction is that of the event's own
    step when other impulses share it (a venting train:
    :func:`~abrupt.detect.attitude.ramp_step.step_siblings`), else the ramp's
    (:func:`~abrupt.detect.attitude.ramp_step.fit_ramp_step`). ``fits``: the event's evidence fits, used
    when they are of this window."""
    fits = _window_fits(table, cleaned_H_N, i0, fits)
    # A train of impulses along the event's own direction is a venting sequence: that direction is the
    # torque's (the ramp fit would take the largest other step, a strike's, for the ramp).
    seq = fits.siblings()
    if seq is not None and seq.sharp_siblings > 0:
        u_b = seq.step_B / float(np.linalg.norm(seq.step_B))
    else:
        fit = fits.ramp()
        if fit is None or not float(np.linalg.norm(fit.ramp_B)) > RAMP_SIGMA_MIN * fit.ramp_sigma:
            return None
        u_b = fit.ramp_B / float(np.linalg.norm(fit.ramp_B))
    q = table.quaternion_BN[a:b]
    y_b = body_frame_momentum(cleaned_H_N[a:b], q)
    # The torque's signal along its direction is taken out and the noise there kept: a running median
    # follows a ramp or a staircase of one sign (a monotone signal is its own median) and leaves the noise.
    # Projecting the direction out left the statistic's pre-window covariance nearly singular along it: on
    # quiet archive stretches its peaks doubled (4.7 → 10-12, above the run's threshold of 6.4), and tiny
    # wobbles (0.001 N·m·s) became "strikes" inside torques.
    k = max(3, round(TORQUE_MEDIAN_S / table.dt_s)) | 1
    along = pd.Series(y_b @ u_b).rolling(k, center=True, min_periods=1).median().to_numpy()
    return _to_inertial(cleaned_H_N[a:b], y_b - along[:, None] * u_b, q)


#: The ramp beside a strike may be a leak as long as the window allows (a ramp starts in the window's middle
#: half and ends 30 s before its end: up to 3/4 of it), on a grid of durations fine enough (ratio 1.1) that
#: a ramp's length is rarely so far off that a shift of its onset into the strike's step fits it better.
LEAK_FRACTION = 0.75
LEAK_DURATIONS = 48


def _without_step(
    table: Timetable,
    cleaned_H_N: FloatArray,
    i0: int,
    a: int,
    b: int,
    fits: WindowFits | None = None,
    neighbours: tuple[Peak, ...] = (),
) -> tuple[FloatArray, RampStep] | None:
    """Cleaned ᴺH over rows [a, b) with the step at row ``i0`` taken out, and the fit, when the window
    around it also holds a ramp beyond its noise (a leak beside a strike); None otherwise. The step is
    that of the step-on-a-ramp fit (:func:`~abrupt.detect.attitude.ramp_step.fit_ramp_step`), fixed in
    body axes at ``i0``, so what is left is the ramp and the rest of the window. The steps of the
    ``neighbours`` (the detector's other peaks) are taken out of the window before the ramp is fitted:
    a second strike minutes away is a change the telemetry shows, and a ramp ending at it is no torque
    of its own. ``fits``: the event's evidence fits, used when they are of this window."""
    fits = _window_fits(table, cleaned_H_N, i0, fits)
    lo, _, hi = fits.key
    y_b = fits.y_B
    for nb in neighbours:  # an impulse is fixed in body axes at its instant (body_frame_momentum)
        on = table.time_ns[lo:hi] >= nb.time_ns
        if on.any() and not on.all():
            k = lo + int(np.argmax(on))
            y_b = y_b - on[:, None] * (dcm_from_quaternion(table.quaternion_BN[k]) @ nb.dH_N_Nms)[None, :]
    # The window's momentum is the evidence's; its ramp fit is not (the leak may be longer than its ramps).
    fit = fit_ramp_step(fits.tau_s, y_b, 0.0, n_durations=LEAK_DURATIONS, max_ramp_fraction=LEAK_FRACTION)
    if fit is None or not float(np.linalg.norm(fit.ramp_B)) > RAMP_SIGMA_MIN * fit.ramp_sigma:
        return None
    g, q = table.time_ns, table.quaternion_BN[a:b]
    y_b = body_frame_momentum(cleaned_H_N[a:b], q)
    return _to_inertial(cleaned_H_N[a:b], y_b - (g[a:b] >= g[i0])[:, None] * fit.step_B[None, :], q), fit


#: After a strike the closed loop hands the impulse from the body to the wheels within its settling time
#: [s]: what the fitted step leaves there is the strike's, not a second source.
SETTLE_S = 30.0


def rescan_after_faults(
    table: Timetable,
    spacecraft: Spacecraft,
    raw_H_N: FloatArray,
    cleaned_H_N: FloatArray,
    ok: BoolArray,
    detector: FlightGlrDetector,
    peaks: list[tuple[int, Peak]],
    evidence: Mapping[int, EventEvidence],
    floor: float,
    keep: BoolArray | None = None,
    inertia_kgm2: FloatArray | None = None,
    rules: AttributionRules | None = None,
    fits: Mapping[int, WindowFits] | None = None,
) -> tuple[list[tuple[int, Peak]], dict[int, EventEvidence], int]:
    """New peaks (above ``floor``), their evidence and how many found twice were merged, found after
    repairing each sensor fault's channel.

    For every peak whose evidence the rules call a ``sensor_fault`` with a channel that has a repair
    model, the channel is corrected, ᴺH recomputed (the cleaning's slow model is kept: cleaned ᴺH moves
    by exactly what the raw ᴺH moved), and the statistic recomputed around the peak; its strongest
    peak from ``RESCAN_SPAN_S`` around the fault's step and at least ``RESCAN_APART_S`` from it becomes
    a new peak, with evidence from the repaired telemetry. For every ``external_non_strike`` peak the
    ramp's body direction is taken out of cleaned ᴺH (:func:`_off_ramp`) and the strongest peak of the
    rest is kept when its evidence (of the telemetry as it is) is a strike's; its look window covers the
    detector's suppression zone around the torque's peak. For every ``strike`` peak whose window also
    holds a ramp, the strike's fitted step is taken out and the rest rescanned
    (:func:`_torque_beside_strike`): a peak there is kept when its evidence is an external torque's.
    ``fits``: each peak's :func:`~abrupt.detect.attitude.evidence.profile_fits` as its evidence made
    them (by peak time).

    No rescan looks within ``RESCAN_APART_S`` of a peak of ``peaks`` (the detector has that step already),
    and one step found by several rescans (a strike between two faults' events, each repaired in turn) is
    one new peak, the strongest (:func:`merge_found`); the third value counts the others.
    """
    g = table.time_ns
    dt = table.dt_s
    win = detector.windows(dt)
    found: list[tuple[int, Peak, EventEvidence]] = []
    half_s = RESCAN_SPAN_S[1] + win.span * dt
    others = tuple((int(p.time_ns), RESCAN_APART_S, RESCAN_APART_S) for _, p in peaks)
    strikes = {t for t, e in evidence.items() if classify(e, rules).kind == "strike"}
    for i_pk, pk in peaks:
        ev = evidence.get(pk.time_ns)
        if ev is None:
            continue
        a_ = classify(ev, rules)
        i0 = int(np.clip(np.searchsorted(g, pk.time_ns), 0, g.size - 1))
        a, b = max(0, i0 - round((half_s + 240.0) / dt)), min(g.size, i0 + round((half_s + 240.0) / dt))
        keep_sub = None if keep is None else keep[a:b]
        if a_.kind == "external_non_strike":
            hc_sub = _off_ramp(table, cleaned_H_N, i0, a, b, None if fits is None else fits.get(pk.time_ns))
            if hc_sub is None:
                continue
            hc_sub = np.where(ok[a:b, None], hc_sub, np.nan)
            # The detector kept one peak per window span around this one: a strike anywhere in that zone
            # (around the statistic's peak sample, which a ramp's located step may sit far from) was hidden.
            t_pk = int(g[min(i_pk, g.size - 1)])
            zone = (min(t_pk - win.span * dt * NS, pk.time_ns + RESCAN_SPAN_S[0] * NS),
                    max(t_pk + win.span * dt * NS, pk.time_ns + RESCAN_SPAN_S[1] * NS))  # fmt: skip
            best = _best_peak(
                detector, hc_sub, ok[a:b], g[a:b], dt, pk.time_ns, floor, keep_sub, (int(zone[0]), int(zone[1])), others
            )
            if best is None:
                continue
            j, p = best
            ev_new = event_evidence(
                table, cleaned_H_N, spacecraft, p.time_ns, p.dH_N_Nms, inertia_kgm2=inertia_kgm2, raw_H_N=raw_H_N
            )
            # Only an impulse of its own is a second source; another piece of the same torque adds nothing.
            if classify(ev_new, rules).kind != "strike":
                continue
            found.append((a + j, p, replace(ev_new, after_torque_s=(p.time_ns - pk.time_ns) / NS)))
            continue
        if a_.kind == "strike":
            got = _torque_beside_strike(
                table, spacecraft, raw_H_N, cleaned_H_N, ok, detector, pk, (i0, a, b), floor, keep_sub, others,
                inertia_kgm2, rules, None if fits is None else fits.get(pk.time_ns),
                tuple(q for _, q in peaks if q.time_ns != pk.time_ns and q.time_ns in strikes),
            )  # fmt: skip
            if got is not None:
                found.append((*got[0], got[1]))
            continue
        if a_.kind != "sensor_fault" or not a_.channel:
            continue
        rep = repair_sensor_fault(table, spacecraft, i0, a_.channel, a_.reason, half_s)
        if rep is None:
            continue
        h_new, _ = timetable_momentum(spacecraft, _rows(rep.table, a, b), inertia_kgm2)
        hc_sub = np.where(ok[a:b, None], cleaned_H_N[a:b] + (h_new - raw_H_N[a:b]), np.nan)
        best = _best_peak(detector, hc_sub, ok[a:b], g[a:b], dt, pk.time_ns, floor, keep_sub, None, others)
        if best is None:
            continue
        j, p = best
        hc_full = cleaned_H_N.copy()
        hc_full[a:b] = hc_sub
        raw_full = raw_H_N.copy()
        raw_full[a:b] = h_new
        ev_new = event_evidence(
            rep.table, hc_full, spacecraft, p.time_ns, p.dH_N_Nms, inertia_kgm2=inertia_kgm2, raw_H_N=raw_full
        )
        found.append((a + j, p, replace(ev_new, after_fault_s=(p.time_ns - pk.time_ns) / NS)))
    return merge_found(found)


def merge_found(
    found: list[tuple[int, Peak, EventEvidence]], resolution_s: float = RESCAN_APART_S
) -> tuple[list[tuple[int, Peak]], dict[int, EventEvidence], int]:
    """The rescans' (row, peak, evidence) one per step: of peaks within ``resolution_s`` of each other (the
    rescans' own resolution: nearer steps cannot be told apart), the strongest with its own evidence; the
    peaks by time, their evidence by peak time, and how many were merged into a stronger one."""
    kept: list[tuple[int, Peak, EventEvidence]] = []
    for j, p, ev in sorted(found, key=lambda c: -c[1].value):
        if not any(abs(p.time_ns - q.time_ns) <= resolution_s * NS for _, q, _ in kept):
            kept.append((j, p, ev))
    kept.sort(key=lambda c: c[1].time_ns)
    return [(j, p) for j, p, _ in kept], {p.time_ns: ev for _, p, ev in kept}, len(found) - len(kept)


def _torque_beside_strike(
    table: Timetable,
    spacecraft: Spacecraft,
    raw_H_N: FloatArray,
    cleaned_H_N: FloatArray,
    ok: BoolArray,
    detector: FlightGlrDetector,
    pk: Peak,
    rows: tuple[int, int, int],
    floor: float,
    keep_sub: BoolArray | None,
    others: tuple[tuple[int, float, float], ...],
    inertia_kgm2: FloatArray | None,
    rules: AttributionRules | None,
    fits: WindowFits | None = None,
    neighbours: tuple[Peak, ...] = (),
) -> tuple[tuple[int, Peak], EventEvidence] | None:
    """A lasting external torque's own peak beside a strike's event, or None (``neighbours``: the
    detector's other peaks that are strikes, whose steps are no torque: :func:`_without_step`).

    A leak whose onset is within a window span of a strike makes one event, at the (larger) strike: the
    strike's fitted step (:func:`_without_step`) is taken out of ᴺH (raw and cleaned alike) and the
    statistic rescanned, outside the loop's settling after the strike. Its strongest peak is kept only
    when its evidence, from the momentum without the strike, is an external torque's (a ramp or a
    sequence); it becomes an event, like any other peak, only above the run's threshold.
    """
    g, dt = table.time_ns, table.dt_s
    i0, a, b = rows
    got = _without_step(table, cleaned_H_N, i0, a, b, fits, neighbours)
    if got is None:
        return None
    hc_sub, fit = np.where(ok[a:b, None], got[0], np.nan), got[1]
    zones = ((int(pk.time_ns), RESCAN_APART_S, SETTLE_S), *others)
    best = _best_peak(detector, hc_sub, ok[a:b], g[a:b], dt, pk.time_ns, floor, keep_sub, avoid=zones, located=False)
    # The torque's event is at the fitted ramp's onset (a ramp has no step of its own for the locator to put
    # the event at), apart from the strike and from every other peak; its ΔH is the ramp's, in inertial axes.
    t_on = int(g[i0]) + int(fit.onset_s * NS)
    if best is None or any(tz - int(lo * NS) <= t_on <= tz + int(hi * NS) for tz, lo, hi in zones):
        return None
    k_on = int(np.clip(np.searchsorted(g, t_on), 0, g.size - 1))
    k_mid = int(np.clip(np.searchsorted(g, t_on + int(0.5 * fit.duration_s * NS)), 0, g.size - 1))
    dh_n = dcm_from_quaternion(table.quaternion_BN[k_mid]).T @ fit.ramp_B
    p = Peak(int(g[k_on]), best[1].value, dh_n, best[1].time_sigma_s)
    shift = np.nan_to_num(hc_sub - cleaned_H_N[a:b])
    hc_full, raw_full = cleaned_H_N.copy(), raw_H_N.copy()
    hc_full[a:b] += shift
    raw_full[a:b] += shift
    ev_new = event_evidence(table, hc_full, spacecraft, p.time_ns, dh_n, inertia_kgm2=inertia_kgm2, raw_H_N=raw_full)
    if classify(ev_new, rules).kind != "external_non_strike":
        return None
    return (k_on, p), replace(ev_new, after_strike_s=(p.time_ns - pk.time_ns) / NS)


#: Classes whose event is one step of total momentum that a second step beside it may hide (a sensor fault's
#: event is repaired instead: :func:`rescan_after_faults`).
STEP_KINDS = ("strike", "external_non_strike")
#: A second step nearer than ``SAME_SEQUENCE_S`` [s] and within ``SAME_SEQUENCE_DEG`` of the first's
#: direction is more of the same change (a dump's further pulses, a venting train's), not a change of its
#: own: the sibling evidence judges those.
SAME_SEQUENCE_S = 60.0
SAME_SEQUENCE_DEG = 20.0


def _impulsive(a: Attribution, ev: EventEvidence, rules: AttributionRules | None = None) -> bool:
    """An impulsive step by its own evidence: a strike, or a dump's step whose time profile is an impulse's
    (a ramp's piece is neither, nor a piece of a longer torque that points against the stored momentum)."""
    if a.kind == "strike":
        return True
    extended = compare_hypotheses(ev).extended
    limit = math.log((rules or AttributionRules()).extended_lr_min)
    return a.reason == DUMP_REASON and not extended > limit


def _shifted(h: FloatArray, g: np.ndarray, steps: list[tuple[int, FloatArray]]) -> FloatArray:
    """``h`` less each (time [ns], ΔH_N) step: a step of total ᴺH from its instant on."""
    out = h.copy()
    for t_ns, d_h in steps:
        out -= (g >= t_ns)[:, None] * np.asarray(d_h)[None, :]
    return out


def neighbours_apart(
    table: Timetable,
    spacecraft: Spacecraft,
    raw_H_N: FloatArray,
    cleaned_H_N: FloatArray,
    ok: BoolArray,
    detector: FlightGlrDetector,
    peaks: list[tuple[int, Peak]],
    evidence: Mapping[int, EventEvidence],
    floor: float,
    keep: BoolArray | None = None,
    inertia_kgm2: FloatArray | None = None,
    rules: AttributionRules | None = None,
) -> tuple[list[tuple[int, Peak]], dict[int, EventEvidence], dict[int, tuple[FloatArray, EventEvidence]]]:
    """Impulsive steps of total momentum hidden beside a step's event, fitted jointly with every step known.

    The detector keeps one peak per window span, so a strike 40 s before a momentum dump leaves one event.
    For every peak whose evidence is a step's (``STEP_KINDS``), the steps of every peak of ``peaks`` near it
    are taken out of ᴺH and the statistic rescanned where the detector suppressed (one window span around
    the peak, as after a ramp); a peak above ``floor`` there, more than ``RESCAN_APART_S`` from every known
    step, is a candidate. It is put where one more step fits best beside the known ones
    (:func:`~abrupt.detect.attitude.steps.best_step_beside`) and all are sized together
    (:func:`~abrupt.detect.attitude.steps.local_steps`); its evidence is taken with the known steps out of
    ᴺH (raw and cleaned), and the event's own with the new step and the other known ones out. It is kept
    when its evidence is an impulsive step's (a strike, a dump) and it is not more of the event's own change
    (within ``SAME_SEQUENCE_S`` and ``SAME_SEQUENCE_DEG``). Returns the new peaks with their evidence
    (``beside_step_s``: the time after the event [s]) and, by peak time, the events' jointly fitted ΔH_N and
    evidence. Nothing is raised between two changes: the new peak is where the telemetry steps once the
    known changes are out, and an event only above the run's threshold.
    """
    g, dt = table.time_ns, table.dt_s
    win = detector.windows(dt)
    found: list[tuple[int, Peak, EventEvidence]] = []
    revised: dict[int, tuple[FloatArray, EventEvidence]] = {}
    known = {int(p.time_ns): np.asarray(p.dH_N_Nms) for _, p in peaks if np.all(np.isfinite(p.dH_N_Nms))}
    half_s = RESCAN_SPAN_S[1] + win.span * dt
    for i_pk, pk in peaks:
        ev = evidence.get(pk.time_ns)
        if ev is None or classify(ev, rules).kind not in STEP_KINDS or pk.time_ns not in known:
            continue
        i0 = int(np.clip(np.searchsorted(g, pk.time_ns), 0, g.size - 1))
        a, b = max(0, i0 - round((half_s + 240.0) / dt)), min(g.size, i0 + round((half_s + 240.0) / dt))
        near = sorted(t for t in known if g[a] < t < g[b - 1])
        hc_sub = np.where(ok[a:b, None], _shifted(cleaned_H_N[a:b], g[a:b], [(t, known[t]) for t in near]), np.nan)
        t_pk = int(g[min(i_pk, g.size - 1)])
        zone = (min(t_pk - int(win.span * dt * NS), pk.time_ns + int(RESCAN_SPAN_S[0] * NS)),
                max(t_pk + int(win.span * dt * NS), pk.time_ns + int(RESCAN_SPAN_S[1] * NS)))  # fmt: skip
        avoid = tuple((t, RESCAN_APART_S, RESCAN_APART_S) for t in known)
        best = _best_peak(
            detector, hc_sub, ok[a:b], g[a:b], dt, pk.time_ns, floor, None if keep is None else keep[a:b], zone, avoid
        )
        if best is None:
            continue
        j = best[0]
        taus = tuple(int(np.searchsorted(g, t + int(0.5 * dt * NS))) for t in near)
        lo, hi = a + j - win.pre, a + j + win.span + 1
        tau = best_step_beside(cleaned_H_N, ok, taus, lo, hi, win.pre, round(RESCAN_APART_S / dt))
        if tau < 0:
            continue
        t_new = int(g[tau]) - int(0.5 * dt * NS)
        sizes = local_steps(cleaned_H_N, ok, (*taus, tau), win.pre, win.guard)
        if not np.all(np.isfinite(sizes)):
            continue
        fitted = dict(zip(near, sizes[:-1], strict=True))
        s1, s2 = fitted[pk.time_ns], sizes[-1]
        cos = float(s1 @ s2) / max(float(np.linalg.norm(s1) * np.linalg.norm(s2)), 1e-300)
        if abs(t_new - pk.time_ns) < SAME_SEQUENCE_S * NS and cos > np.cos(np.radians(SAME_SEQUENCE_DEG)):
            continue
        out_new = list(fitted.items())
        ev2 = event_evidence(
            table, _shifted(cleaned_H_N, g, out_new), spacecraft, t_new, s2,
            inertia_kgm2=inertia_kgm2, raw_H_N=_shifted(raw_H_N, g, out_new),
        )  # fmt: skip
        if not _impulsive(classify(ev2, rules), ev2, rules):
            continue
        out_pk = [(t, s) for t, s in out_new if t != pk.time_ns] + [(t_new, s2)]
        ev1 = event_evidence(
            table, _shifted(cleaned_H_N, g, out_pk), spacecraft, pk.time_ns, s1,
            inertia_kgm2=inertia_kgm2, raw_H_N=_shifted(raw_H_N, g, out_pk),
        )  # fmt: skip
        p = Peak(t_new, best[1].value, s2, best[1].time_sigma_s)
        found.append((a + j, p, replace(ev2, beside_step_s=(t_new - pk.time_ns) / NS)))
        revised[pk.time_ns] = (s1, ev1)
        known[t_new] = s2
    kept, kept_ev, _ = merge_found(found)
    return kept, kept_ev, revised
