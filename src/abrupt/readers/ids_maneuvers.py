"""Operator maneuver histories in the International DORIS Service (IDS) format (``*man.txt``).

One line per maneuver (a window that holds one or more burns)::

    SAT   YYYY DDD HH MM  YYYY DDD HH MM  [flag]  TTT  N  burn_1 ... burn_N

with the window begin and end, an optional flag, the parameter-type code ``TTT`` and the number of
burns ``N``; each burn has 15 tokens: epoch ``YYYY DDD HH MM SS.sss`` (TAI), duration (s), three
velocity-change components (m/s), three accelerations and three acceleration changes. Days are days
of year counted from 1 (1 January is day 001): the benchmark dataset of Shorten et al. added the day
of year to 1 January and so is one day late (``../shared/data/PROVENANCE.md``); here day ``DDD`` is
``1 January + (DDD - 1) days``.

The component order depends on the parameter type; abrupt maps it to its orbit frame
(radial, along-track, cross-track; DESIGN.md) as follows (assumptions, documented in docs/tle.md):

``007`` (Jason)            Q, S, W  = radial, along-track, cross-track;
``006`` (Sentinel/CryoSat) radial, along-track, cross-track;
``005`` (SPOT)             T, R, L  = along-track, radial, cross-track.

Epochs are converted from TAI to UTC with astropy's leap-second table
(:func:`abrupt.model.timescales.to_utc`).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
from erfa import ErfaWarning

from abrupt.errors import InputError, RepairLog
from abrupt.model.timescales import to_utc
from abrupt.readers.compression import read_text
from abrupt.readers.timesystems import day_of_year_date

BURN_TOKENS = 15
COMPONENT_ORDER: dict[str, tuple[int, int, int]] = {
    # index of (radial, along-track, cross-track) among the three delta-v tokens
    "007": (0, 1, 2),
    "006": (0, 1, 2),
    "005": (1, 0, 2),
}

MANEUVER_COLUMNS: tuple[str, ...] = (
    "spacecraft",
    "time_utc",
    "window_start_utc",
    "window_end_utc",
    "n_burns",
    "duration_s",
    "dv_r_mps",
    "dv_t_mps",
    "dv_n_mps",
    "dv_mps",
    "dv_n_abs_mps",
    "parameter_type",
    "line",
)


def _doy_time(tokens: list[str], file: str, line_no: int, what: str) -> np.datetime64:
    """``YYYY DDD HH MM [SS.sss]`` → datetime64 (same time scale as the file)."""
    try:
        year, doy, hh, mm = (int(t) for t in tokens[:4])
        sec = float(tokens[4]) if len(tokens) > 4 else 0.0
    except ValueError:
        raise InputError(
            f"{what}: cannot read {' '.join(tokens)!r} as year, day of year, time", file=file, line=line_no
        ) from None
    if not (1960 <= year <= 2100 and 0 <= hh <= 23 and 0 <= mm <= 59 and 0.0 <= sec < 61.0):
        raise InputError(f"{what}: {' '.join(tokens)!r} is not a valid year/day-of-year/time", file=file, line=line_no)
    try:
        base = day_of_year_date(year, doy)
    except ValueError as exc:
        raise InputError(f"{what}: {' '.join(tokens)!r}: {exc}", file=file, line=line_no) from None
    offset_ns = round(((hh * 60 + mm) * 60 + sec) * 1e9)
    return base + np.timedelta64(offset_ns, "ns")


MAX_ABS_VALUE = 1e6  # [s, m/s, m/s^2]: a burn duration, delta-v or acceleration beyond this is no burn


def read_ids_maneuvers(path: str | Path, *, repairs: RepairLog | None = None) -> pd.DataFrame:
    """Read an IDS maneuver file: one row per maneuver window, times in UTC.

    Columns (:data:`MANEUVER_COLUMNS`): ``time_utc`` is the first burn's epoch, ``dv_*`` the sum of
    the burns' components in the orbit frame (m/s), ``dv_mps`` the sum of burn magnitudes,
    ``dv_n_abs_mps`` the sum of the burns' |cross-track| components (a pair of opposite cross-track
    burns half an orbit apart turns the orbit plane by both, while their summed components net to zero),
    ``duration_s`` the total burn time. Exact duplicate lines are dropped and counted; rows are
    sorted by time (counted when the file was out of order).
    """
    path = Path(path)
    file = str(path)
    repairs = repairs if repairs is not None else RepairLog(source=file)
    rows = []
    burn_tai: list[np.datetime64] = []
    seen: set[str] = set()
    duplicates = 0
    for line_no, raw in enumerate(
        read_text(path, encoding="ascii", what="IDS maneuver", decompress=False).splitlines(), start=1
    ):
        text = raw.strip()
        if not text or text.startswith("#"):
            continue
        if text in seen:
            duplicates += 1
            continue
        seen.add(text)
        tok = text.split()
        if len(tok) < 11:
            raise InputError(f"maneuver line has {len(tok)} fields, expected at least 11", file=file, line=line_no)
        head = 9
        # optional flag: the parameter type is a 3-digit code followed by the burn count N
        if len(tok) > head + 2 and len(tok[head + 1]) <= 3 and (len(tok) - head - 3) % BURN_TOKENS == 0:
            head += 1  # a flag is present
        ptype, n_text = tok[head], tok[head + 1]
        try:
            n_burns = int(n_text)
        except ValueError:
            raise InputError(f"number of burns {n_text!r} is not an integer", file=file, line=line_no) from None
        burns = tok[head + 2 :]
        if n_burns < 1 or len(burns) != n_burns * BURN_TOKENS:
            raise InputError(
                f"{n_burns} burn(s) announced but {len(burns)} burn tokens found (expected {BURN_TOKENS} per burn)",
                file=file,
                line=line_no,
            )
        if ptype not in COMPONENT_ORDER:
            raise InputError(
                f"unknown parameter-type code {ptype!r} (known: {sorted(COMPONENT_ORDER)})",
                file=file,
                line=line_no,
            )
        order = COMPONENT_ORDER[ptype]
        win0 = _doy_time(tok[1:5], file, line_no, "window begin")
        win1 = _doy_time(tok[5:9], file, line_no, "window end")
        dv = np.zeros(3)
        mag = 0.0
        cross_abs = 0.0
        duration = 0.0
        first: np.datetime64 | None = None
        for b in range(n_burns):
            bt = burns[b * BURN_TOKENS : (b + 1) * BURN_TOKENS]
            epoch = _doy_time(bt[:5], file, line_no, f"burn {b + 1} epoch")
            try:
                duration += float(bt[5])
                comps = np.array([float(x) for x in bt[6:9]])
                values = [float(x) for x in bt[5:]]
            except ValueError:
                raise InputError(
                    f"burn {b + 1}: duration, delta-v or acceleration is not a number", file=file, line=line_no
                ) from None
            if not all(abs(v) < MAX_ABS_VALUE for v in values):  # NaN fails the comparison too
                raise InputError(
                    f"burn {b + 1}: a duration, delta-v or acceleration that is not finite or beyond "
                    f"{MAX_ABS_VALUE:g} in magnitude",
                    file=file,
                    line=line_no,
                )
            vec = comps[list(order)]
            dv += vec
            mag += float(np.linalg.norm(vec))
            cross_abs += abs(float(vec[2]))
            burn_tai.append(epoch)
            first = epoch if first is None else min(first, epoch)
        rows.append(
            dict(
                spacecraft=tok[0],
                time_utc=first,
                window_start_utc=win0,
                window_end_utc=win1,
                n_burns=n_burns,
                duration_s=duration,
                dv_r_mps=dv[0],
                dv_t_mps=dv[1],
                dv_n_mps=dv[2],
                dv_mps=mag,
                dv_n_abs_mps=cross_abs,
                parameter_type=ptype,
                line=line_no,
            )
        )
    repairs.record("duplicate maneuver lines dropped", duplicates)
    if not rows:
        raise InputError("no maneuvers (no maneuver line: an empty or cut file?)", file=file, line=1)
    frame = pd.DataFrame(rows, columns=list(MANEUVER_COLUMNS))
    with warnings.catch_warnings():
        # ERFA calls years past its leap-second table "dubious"; TAI−UTC is then held at the last value
        warnings.simplefilter("ignore", ErfaWarning)
        for col in ("time_utc", "window_start_utc", "window_end_utc"):
            frame[col] = to_utc(frame[col].to_numpy(dtype="datetime64[ns]"), "tai")
    if not frame["time_utc"].is_monotonic_increasing:
        repairs.record("maneuvers out of time order, sorted", 1)
        frame = frame.sort_values("time_utc", kind="stable")
    return frame.reset_index(drop=True)
