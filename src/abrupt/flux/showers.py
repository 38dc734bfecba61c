"""Meteoroid shower calendar and the test of association of detections with shower peaks.

The calendar (``abrupt/data/meteor_showers.csv``) lists 13 major annual showers as published in the IMO
Working List of Visual Meteor Showers (source and edition in the file's header): activity period, peak
date, zenithal hourly rate at the peak (empty where the list gives no fixed rate), geocentric speed and,
where checked against a published IMO value, the solar longitude of the peak. A shower's
*peak window* is the peak day ± ``half_width_days`` (default 2): the ZHR falls to a fraction of its peak
within a few days for most showers.

Test of association: if detections are unrelated to the showers, the number k of events inside the
peak windows is binomial with n = all events and p = the share of the exposure (analysed spacecraft-
days) that falls inside the windows. The one-sided p-value P(K >= k) is exact (no large-sample
approximation). Note that a shower's *visual* ZHR counts millimetre-to-centimetre meteors in the
atmosphere, whereas a detectable strike needs a particle of roughly 0.1-1 mm and above at tens of km/s:
the showers' share of the sporadic flux at those sizes is small (of order 10 % at the peak of the
strongest), so a fleet needs many events to see them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

CALENDAR_PATH = Path(__file__).resolve().parent.parent / "data" / "meteor_showers.csv"


def shower_calendar(path: str | Path = CALENDAR_PATH) -> pd.DataFrame:
    """The shower table with day-of-year of start, peak and end (non-leap year)."""
    table = pd.read_csv(path, comment="#")
    for col in ("start", "peak", "end"):
        table[f"{col}_doy"] = pd.to_datetime("2001-" + table[f"{col}_mmdd"], format="%Y-%m-%d").dt.day_of_year
    return table


def _doy(days: pd.Series) -> np.ndarray:
    """Day of year 1..365 (29 February counted with 28 February)."""
    d = pd.to_datetime(days.astype(str).str[:10], format="%Y-%m-%d")
    doy = d.dt.day_of_year.to_numpy()
    leap = d.dt.is_leap_year.to_numpy() & (doy > 59)
    return np.asarray(doy - leap, dtype=np.int64)


def in_window(doy: np.ndarray, peak_doy: int, half_width_days: int) -> np.ndarray:
    """Whether days of year lie within ± half_width of a peak (wrapping the year end)."""
    d = np.abs(doy - peak_doy)
    return np.minimum(d, 365 - d) <= half_width_days


def shower_association(
    exposure: pd.DataFrame, events: pd.DataFrame, *, half_width_days: int = 2
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Events and exposure per day of year, and the binomial test per shower and for all peaks together."""
    f = exposure["analysed_fraction"].to_numpy(dtype=np.float64)
    exp_doy = _doy(exposure["day"])
    ev = events[events["kind"].astype(str) == "strike"] if len(events) else events
    ev_doy = _doy(ev["time_utc"]) if len(ev) else np.zeros(0, dtype=np.int64)
    per_day = pd.DataFrame(
        {
            "day_of_year": np.arange(1, 366),
            "events": np.bincount(ev_doy, minlength=367)[1:366],
            "exposure_days": np.bincount(exp_doy, weights=f, minlength=367)[1:366],
        }
    )
    cal = shower_calendar()
    rows = []
    total_exp, n = float(f.sum()), int(ev_doy.size)
    any_ev = np.zeros(ev_doy.size, dtype=bool)
    any_ex = np.zeros(exp_doy.size, dtype=bool)
    for rec in cal.to_dict("records"):
        we, wx = (
            in_window(ev_doy, int(rec["peak_doy"]), half_width_days),
            in_window(exp_doy, int(rec["peak_doy"]), half_width_days),
        )
        any_ev |= we
        any_ex |= wx
        rows.append(_test(str(rec["code"]), int(we.sum()), n, float(f[wx].sum()), total_exp, rec["zhr"]))
    rows.append(_test("ALL", int(any_ev.sum()), n, float(f[any_ex].sum()), total_exp, float(cal["zhr"].sum())))
    return per_day, pd.DataFrame(rows)


def _test(code: str, k: int, n: int, exp_in: float, exp_total: float, zhr: float) -> dict[str, float | str]:
    p = exp_in / exp_total if exp_total > 0 else 0.0
    return {
        "shower": code,
        "zhr": float(zhr),
        "events_in_window": k,
        "events_expected": n * p,
        "exposure_share": p,
        "p_value": float(stats.binom.sf(k - 1, n, p)) if n and p > 0 else 1.0,
    }
