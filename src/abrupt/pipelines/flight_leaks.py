"""The leak scan's findings as events (:mod:`abrupt.detect.attitude.leak_scan`).

Each leak is one ``external_non_strike`` event (detector ``attitude.leak_scan``) at its onset, with its
duration, its body torque (vector and magnitude), its total ᴺH change and the ramp's log likelihood
ratio over the step models in ``leak_*`` columns, its statistic and threshold in σ of the scan's noise,
and the rate that threshold was set for. The step detector scans the cleaned ᴺH with the leaks' ramps
taken out (:mod:`abrupt.pipelines.flight_cleaning`); a step event it still raises within a leak's
interval (± ``LEAK_MARGIN_S``) classed ``external_non_strike`` or ``unknown`` is the leak's (the step
detector answers its onset and end) and is dropped, counted in ``attrs["leak_events_absorbed"]``. A strike
within a leak is a step on the ramp and keeps its own event, and so does a sensor fault.

A ramp that begins or ends within ``FAULT_MARGIN_S`` of a sensor fault's event is that fault's: a gyro
bias step moves the measured momentum at once and then drifts as the attitude estimate takes the bias
in, which a ramp fits. The fault explains it, so no leak is reported (counted in
``attrs["leaks_explained_by_faults"]``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from abrupt.detect.attitude.leak_scan import LeakFinding
from abrupt.events import Event, event_ids, event_times_ns, events_frame, format_time_utc
from abrupt.series.timetable import NS

LEAK_DETECTOR = "attitude.leak_scan"
STEP_DETECTOR = "attitude.flight_glr"
#: A non-strike step event this close [s] to a leak's interval is the leak's.
LEAK_MARGIN_S = 60.0
#: A ramp beginning or ending this close [s] to a sensor fault's event is the fault's.
FAULT_MARGIN_S = 120.0


def leak_events(leaks: Sequence[LeakFinding], spacecraft: str, run_id: str, cfg_hash: str) -> pd.DataFrame:
    """One event per leak (module docstring)."""
    rows = []
    for f in leaks:
        tq = np.asarray(f.torque_B_Nm, float)
        dh_b = np.asarray(f.dH_B_Nms, float)
        extra = {
            "statistic_units": "sigma",
            "threshold_method": "upcrossing-tail",
            "leak_end_utc": format_time_utc(np.datetime64(f.end_ns, "ns")),
            "leak_duration_s": f.duration_s,
            "leak_torque_B_x_Nm": tq[0],
            "leak_torque_B_y_Nm": tq[1],
            "leak_torque_B_z_Nm": tq[2],
            "leak_torque_Nm": float(np.linalg.norm(tq)),
            "leak_dH_B_Nms": float(np.linalg.norm(dh_b)),
            "leak_log_lr": f.log_lr,
        }
        rows.append(
            Event(
                spacecraft=spacecraft,
                kind="external_non_strike",
                detector=LEAK_DETECTOR,
                time_utc=format_time_utc(np.datetime64(f.onset_ns, "ns")),
                time_sigma_s=30.0,
                statistic=f.statistic,
                threshold=f.threshold,
                false_alarms_per_day=f.false_alarms_per_day,
                run_id=run_id,
                config_hash=cfg_hash,
                dH_N_x_Nms=float(f.dH_N_Nms[0]),
                dH_N_y_Nms=float(f.dH_N_Nms[1]),
                dH_N_z_Nms=float(f.dH_N_Nms[2]),
                extra=extra,
            )
        )
    frame = events_frame(rows)
    frame["kind_channel"] = pd.Series(["momentum"] * len(rows), dtype="string")
    frame["kind_reason"] = pd.Series(
        [f"sustained external torque {np.linalg.norm(f.torque_B_Nm):.2g} N·m for {f.duration_s:.0f} s: a ramp of "
         "the body-axis momentum (thruster leak)" for f in leaks], dtype="string")  # fmt: skip
    frame["kind_confidence"] = [1.0 / (1.0 + math.exp(-min(f.log_lr, 50.0))) for f in leaks]
    return frame


def merge_leaks(
    events: pd.DataFrame, leaks: Sequence[LeakFinding], spacecraft: str, run_id: str, cfg_hash: str
) -> pd.DataFrame:
    """``events`` with one event per leak added and the leaks' own step events dropped, less the leaks a sensor
    fault explains (module docstring)."""
    n_leaks = len(leaks)
    out = events.copy()
    out.attrs["leak_events_absorbed"] = 0
    t_ev = event_times_ns(out)
    kinds = out["kind"].astype(str).to_numpy() if len(out) else np.empty(0, str)
    t_fault = t_ev[kinds == "sensor_fault"]
    fault_ns = int(FAULT_MARGIN_S * NS)
    leaks = [
        f
        for f in leaks
        if not any(np.min(np.abs(t_fault - t)) <= fault_ns for t in (f.onset_ns, f.end_ns) if t_fault.size)
    ]
    out.attrs["leaks_explained_by_faults"] = n_leaks - len(leaks)
    if not leaks:
        return out
    steps = out["detector"].astype(str).to_numpy() == STEP_DETECTOR if len(out) else np.empty(0, bool)
    margin = int(LEAK_MARGIN_S * NS)
    inside = np.zeros(len(out), bool)
    for f in leaks:
        inside |= (t_ev >= f.onset_ns - margin) & (t_ev <= f.end_ns + margin)
    drop = inside & steps & np.isin(kinds, ("external_non_strike", "unknown"))
    kept = out.loc[~drop]
    new = leak_events(leaks, spacecraft, run_id, cfg_hash)
    merged = pd.concat([kept, new], ignore_index=True) if len(kept) else new
    merged["event_id"] = event_ids(merged)
    merged = merged.sort_values("time_utc", kind="stable").reset_index(drop=True)
    merged.attrs["leak_events_absorbed"] = int(drop.sum())
    merged.attrs["leaks_explained_by_faults"] = out.attrs["leaks_explained_by_faults"]
    return merged
