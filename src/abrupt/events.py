"""The one event schema every detector returns (README, "What it does").

A detector returns a :class:`pandas.DataFrame` whose first columns are exactly
:data:`EVENT_COLUMNS`, in that order; further columns may follow. A value a detector does not
estimate is empty (NaN). A detector that finds nothing returns :func:`empty_frame`, which has the
same columns and no rows. An event's ``kind`` is one of :data:`EVENT_KINDS`, the vocabulary of
:mod:`abrupt.kinds` (its ``EVENT_KIND_MEANINGS`` says what each means and which detectors write it).

Event identifiers are deterministic (a hash of spacecraft, detector, kind, time and configuration
hash), so re-running the same input and configuration yields the same ``event_id`` and the catalog
does not duplicate events.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import uuid
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field, is_dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from abrupt.kinds import EVENT_KINDS
from abrupt.outputs import atomic_output

EVENT_COLUMNS: tuple[str, ...] = (
    "event_id",
    "spacecraft",
    "kind",
    "detector",
    "time_utc",
    "time_sigma_s",
    "statistic",
    "threshold",
    "false_alarms_per_day",
    "dH_N_x_Nms",
    "dH_N_y_Nms",
    "dH_N_z_Nms",
    "dH_Nms",
    "dv_r_mps",
    "dv_t_mps",
    "dv_n_mps",
    "dv_mps",
    "run_id",
    "config_hash",
)

#: Schema columns holding text (identifiers, names, ISO-8601 times); the others are float64.
TEXT_COLUMNS: tuple[str, ...] = ("event_id", "spacecraft", "kind", "detector", "time_utc", "run_id", "config_hash")
FLOAT_COLUMNS: tuple[str, ...] = tuple(c for c in EVENT_COLUMNS if c not in TEXT_COLUMNS)
_FLOAT_COLUMNS = FLOAT_COLUMNS

NAN = float("nan")


def config_hash(config: Mapping[str, Any] | Any) -> str:
    """Stable 16-hex-digit hash of a configuration (a mapping or a dataclass), for ``config_hash``."""
    if is_dataclass(config) and not isinstance(config, type):
        config = asdict(config)
    text = json.dumps(config, sort_keys=True, default=_json_default)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def run_config_hash(settings: Mapping[str, Any], budget: object, *, detector: str | None = None) -> str:
    """The ``config_hash`` of ``settings`` run at a false-alarm ``budget`` (by ``detector`` if named):
    ``config_hash({"detector": detector, **settings, "budget": str(budget)})``, spelled once."""
    named = {"detector": detector} if detector is not None else {}
    return config_hash({**named, **settings, "budget": str(budget)})


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return str(obj)


def new_run_id() -> str:
    """A fresh identifier for one run of a command."""
    return uuid.uuid4().hex[:16]


def make_event_id(spacecraft: str, detector: str, kind: str, time_utc: str, cfg_hash: str) -> str:
    """Deterministic event identifier: same input and configuration give the same id."""
    key = "|".join((spacecraft, detector, kind, time_utc, cfg_hash))
    return hashlib.sha256(key.encode()).hexdigest()[:20]


def event_ids(frame: pd.DataFrame) -> pd.Series:
    """Every row's ``event_id`` from its own columns (:func:`make_event_id`): after a row's ``kind``
    changed, its identifier changes with it."""
    ids = [
        make_event_id(str(r.spacecraft), str(r.detector), str(r.kind), str(r.time_utc), str(r.config_hash))
        for r in frame[["spacecraft", "detector", "kind", "time_utc", "config_hash"]].itertuples()
    ]
    return pd.Series(ids, index=frame.index, dtype="string")


def event_times_ns(frame: pd.DataFrame, column: str = "time_utc") -> np.ndarray:
    """The events' times [ns since 1970, UTC] from ``column`` (ISO-8601 text, ``Z`` or not, or datetimes)."""
    if not len(frame):
        return np.zeros(0, dtype=np.int64)
    t = pd.to_datetime(frame[column].astype(str), utc=True, format="ISO8601")
    return np.asarray(t.dt.tz_localize(None).to_numpy(dtype="datetime64[ns]").astype(np.int64))


def format_time_utc(t: Any) -> str:
    """ISO-8601 UTC with microseconds and a ``Z`` suffix, from datetime64, Timestamp or string."""
    ts = pd.Timestamp(t)
    if ts.tzinfo is not None:
        ts = ts.tz_convert("UTC").tz_localize(None)
    return ts.strftime("%Y-%m-%dT%H:%M:%S.%fZ")


@dataclass(frozen=True)
class Event:
    """One detected abrupt momentum change. Units in the field names; NaN where not estimated.

    ``dH_N_*`` is the angular momentum change in the inertial frame N (N·m·s); ``dv_*`` the
    velocity change in the orbit frame (radial, along-track, cross-track; m/s).
    """

    spacecraft: str
    kind: str
    detector: str
    time_utc: str
    statistic: float
    threshold: float
    false_alarms_per_day: float
    run_id: str
    config_hash: str
    time_sigma_s: float = NAN
    dH_N_x_Nms: float = NAN
    dH_N_y_Nms: float = NAN
    dH_N_z_Nms: float = NAN
    dH_Nms: float = NAN
    dv_r_mps: float = NAN
    dv_t_mps: float = NAN
    dv_n_mps: float = NAN
    dv_mps: float = NAN
    extra: Mapping[str, Any] = field(default_factory=dict)
    event_id: str = ""

    def __post_init__(self) -> None:
        if self.kind not in EVENT_KINDS:
            raise ValueError(f"event kind {self.kind!r} is not one of {EVENT_KINDS}")
        if not self.spacecraft:
            raise ValueError("event spacecraft pseudonym is empty")
        if not self.detector:
            raise ValueError("event detector name is empty")
        object.__setattr__(self, "time_utc", format_time_utc(self.time_utc))
        for name in _FLOAT_COLUMNS:
            object.__setattr__(self, name, float(getattr(self, name)))
        if self.time_sigma_s < 0:
            raise ValueError(f"time_sigma_s must be >= 0, got {self.time_sigma_s}")
        # Fill magnitudes from components when a detector gave only the vector.
        dh = (self.dH_N_x_Nms, self.dH_N_y_Nms, self.dH_N_z_Nms)
        if math.isnan(self.dH_Nms) and not any(math.isnan(c) for c in dh):
            object.__setattr__(self, "dH_Nms", math.sqrt(sum(c * c for c in dh)))
        dv = (self.dv_r_mps, self.dv_t_mps, self.dv_n_mps)
        if math.isnan(self.dv_mps) and not any(math.isnan(c) for c in dv):
            object.__setattr__(self, "dv_mps", math.sqrt(sum(c * c for c in dv)))
        if not self.event_id:
            object.__setattr__(
                self,
                "event_id",
                make_event_id(self.spacecraft, self.detector, self.kind, self.time_utc, self.config_hash),
            )

    def as_row(self) -> dict[str, Any]:
        row = {name: getattr(self, name) for name in EVENT_COLUMNS}
        row.update(self.extra)
        return row


def empty_frame(extra_columns: Iterable[str] = ()) -> pd.DataFrame:
    """The event frame with no rows: same columns and dtypes as a frame with events."""
    return _empty_template(tuple(dict.fromkeys(extra_columns))).copy()


@functools.lru_cache(maxsize=64)
def _empty_template(extra_columns: tuple[str, ...]) -> pd.DataFrame:
    # Built once per column set: normalising a frame costs ~10 ms, paid per object of a catalogue.
    return events_frame([], extra_columns=extra_columns)


def events_frame(events: Iterable[Event], extra_columns: Iterable[str] = ()) -> pd.DataFrame:
    """Frame of events with :data:`EVENT_COLUMNS` first, in order, then any extra columns."""
    rows = [e.as_row() for e in events]
    extra = list(dict.fromkeys([*extra_columns, *(k for r in rows for k in r if k not in EVENT_COLUMNS)]))
    frame = pd.DataFrame(rows, columns=[*EVENT_COLUMNS, *extra])
    return normalise_frame(frame)


def normalise_frame(frame: pd.DataFrame) -> pd.DataFrame:
    """Check and coerce a frame to the event schema: required columns first, in order, with dtypes."""
    missing = [c for c in EVENT_COLUMNS if c not in frame.columns]
    if missing:
        raise ValueError(f"event frame lacks required columns {missing}")
    ordered = [*EVENT_COLUMNS, *(c for c in frame.columns if c not in EVENT_COLUMNS)]
    out = frame.loc[:, ordered].copy()
    for name in _FLOAT_COLUMNS:
        out[name] = pd.to_numeric(out[name], errors="raise").astype("float64")
    if pd.api.types.is_datetime64_any_dtype(out["time_utc"]):  # typed timestamps (Parquet) to the ISO text form
        out["time_utc"] = [format_time_utc(t) for t in out["time_utc"]]
    for name in TEXT_COLUMNS:
        out[name] = out[name].astype("string")
    bad = ~out["kind"].isin(EVENT_KINDS)
    if bad.any():
        raise ValueError(f"event kinds {sorted(set(out.loc[bad, 'kind']))} not in {EVENT_KINDS}")
    return out.reset_index(drop=True)


def restamp(frame: pd.DataFrame, *, run_id: str, config_hash: str) -> pd.DataFrame:
    """The events of one run: ``run_id`` and the run's ``config_hash`` set, ``event_id`` recomputed.

    A detector run on its own stamps its own configuration; a pipeline that runs several detectors
    under one configuration stamps them all with it, so identifiers stay deterministic per run
    configuration (:func:`make_event_id`).
    """
    out = normalise_frame(frame)
    out["run_id"] = pd.array([run_id] * len(out), dtype="string")
    out["config_hash"] = pd.array([config_hash] * len(out), dtype="string")
    ids = [
        make_event_id(str(sc), str(det), str(kind), str(t), config_hash)
        for sc, det, kind, t in zip(out["spacecraft"], out["detector"], out["kind"], out["time_utc"], strict=True)
    ]
    out["event_id"] = pd.array(ids, dtype="string")
    return out


def _format_time_cell(value: Any) -> Any:
    """One cell of a ``*_utc`` detail column in the export format (``;``-separated lists item by item)."""
    if value is None or (isinstance(value, float) and math.isnan(value)) or value is pd.NaT:
        return value
    try:
        return ";".join(format_time_utc(part) for part in str(value).split(";")) if str(value) else value
    except (ValueError, TypeError):
        return value


def format_time_columns(frame: pd.DataFrame) -> pd.DataFrame:
    """Every ``*_utc`` column of ``frame`` (detail columns too) in the one export time format,
    ISO-8601 UTC with a ``Z`` (:func:`format_time_utc`); a cell that is not a time is left as it is."""
    out = frame.copy()
    for col in out.columns:
        if str(col).endswith("_utc") and col != "time_utc":
            out[col] = [_format_time_cell(v) for v in out[col]]
    return out


def write_events(frame: pd.DataFrame, path: str) -> None:
    """Write events to CSV or Parquet, chosen by the file suffix (``.csv``, ``.parquet``/``.pq``).

    Parquet stores ``time_utc`` as a typed UTC timestamp (microseconds); CSV as ISO-8601 text. The file
    is written beside ``path`` under a temporary name and renamed over it (an interrupted write leaves
    the previous file whole; a symbolic link at ``path`` is replaced, not followed).
    """
    frame = normalise_frame(frame)
    lower = str(path).lower()
    if not lower.endswith((".parquet", ".pq", ".csv")):
        raise ValueError(f"{path}: events file must end in .csv or .parquet")
    with atomic_output(path) as tmp_name:
        if lower.endswith(".csv"):
            frame.to_csv(tmp_name, index=False)
        else:
            typed = frame.copy()
            typed["time_utc"] = pd.to_datetime(typed["time_utc"].astype(str), utc=True).astype("datetime64[us, UTC]")
            typed.to_parquet(tmp_name, index=False)


def read_events(path: str) -> pd.DataFrame:
    """Read an events file written by :func:`write_events` and check it against the schema."""
    lower = str(path).lower()
    if lower.endswith((".parquet", ".pq")):
        frame = pd.read_parquet(path)
    else:
        # identifiers stay text: a hash like "12345e67" or a pseudonym "007" must not become a number
        frame = pd.read_csv(
            path,
            dtype={c: str for c in TEXT_COLUMNS},
            keep_default_na=False,
            na_values={c: [""] for c in _FLOAT_COLUMNS},
        )
    return normalise_frame(frame)


# ------------------------------------------------------------------------------ attribution evidence
EVIDENCE_PREFIX = "ev_"
"""Columns of attribution evidence (``ev_min_dv_mps``, ``ev_orbit_dv_mps``, ...): written to their own
table keyed by ``event_id`` (:func:`write_events_and_evidence`), not beside the event."""


def evidence_path(path: str | Path) -> Path:
    """The evidence table beside an events file: ``events.csv`` → ``events.evidence.csv``,
    ``events.parquet`` → ``events.evidence.parquet``."""
    p = Path(path)
    return p.with_name(f"{p.stem}.evidence{p.suffix}")


def split_evidence(frame: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(the event table without ``ev_*`` columns, the evidence table: ``event_id`` and the ``ev_*`` columns).

    The evidence table has only ``event_id`` when the events carry no evidence.
    """
    names = [c for c in frame.columns if str(c).startswith(EVIDENCE_PREFIX)]
    evidence = frame[["event_id", *names]].copy() if "event_id" in frame else pd.DataFrame({"event_id": []})
    return frame.drop(columns=names), evidence.reset_index(drop=True)


def write_evidence(evidence: pd.DataFrame, path: str | Path) -> None:
    """Write an evidence table (keyed by ``event_id``) to CSV or Parquet, chosen by the suffix, atomically."""
    with atomic_output(path) as tmp:
        if str(path).lower().endswith(".csv"):
            evidence.to_csv(tmp, index=False)
        else:
            evidence.to_parquet(tmp, index=False)


def write_events_and_evidence(frame: pd.DataFrame, path: str) -> Path | None:
    """Write the event table to ``path`` (:func:`write_events`) and, when the events carry attribution
    evidence, the evidence table to :func:`evidence_path` (same format, keyed by ``event_id``; written
    first). Both are written aside and renamed into place. Returns the evidence file, or None when there
    was no evidence."""
    events, evidence = split_evidence(normalise_frame(frame))
    target = None
    if evidence.shape[1] > 1:
        target = evidence_path(path)
        if target.resolve() == Path(path).resolve():
            raise ValueError(f"{path}: the evidence table would overwrite the events file")
        write_evidence(evidence, target)
    write_events(events, path)
    return target


def read_evidence(path: str | Path) -> pd.DataFrame:
    """The evidence table written beside an events file (``event_id`` as text; empty when there is none)."""
    target = evidence_path(path)
    if not target.is_file():
        return pd.DataFrame({"event_id": pd.Series([], dtype="string")})
    if target.suffix.lower() == ".csv":
        frame = pd.read_csv(target, dtype={"event_id": str})
    else:
        frame = pd.read_parquet(target)
    frame["event_id"] = frame["event_id"].astype("string")
    return frame
