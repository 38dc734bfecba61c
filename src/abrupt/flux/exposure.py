"""Exposure per spacecraft-day: what a day of analysed telemetry could have detected.

A day's exposure is the time analysed (``analysed_fraction`` of the day), the detection efficiency
against the size of the momentum change, ε(|ΔH|), the false-alarm rate the threshold was set for, and
what the forward model needs to turn a flux into strikes: the orbit (altitude, inclination, epoch), the
spacecraft file (mass and ``[[surfaces]]``) and whether the body axes are the orbit axes (a nadir-
pointing spacecraft: then the direction of ΔH in the orbit frame is known).

The efficiency is a logistic curve in ln|ΔH| with a plateau,

    ε(x) = ε_max / (1 + exp(-k (ln x - ln x50))),

fitted by maximum likelihood to injection-recovery outcomes (found or not per injected size; the flight
pipeline's ``--recovery``), so ΔH90 = x50 · 9^(1/k) when ε_max = 1.

Exposure rows live in the catalog beside the events (table ``exposure``, created by abrupt next to the
event tables; one row per spacecraft, day, detector and configuration), so a catalog carries both halves
of a flux measurement.
"""

from __future__ import annotations

import csv
import datetime as dt
import hashlib
import math
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import sqlalchemy as sa
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from abrupt.catalog import Catalog
from abrupt.errors import ConfigError, InputError
from abrupt.model.spacecraft import Spacecraft, load_spacecraft, spacecraft_from_dict

DAYS_PER_YEAR = 365.25  # [d] Julian year

EXPOSURE_COLUMNS: tuple[str, ...] = (
    "spacecraft",
    "day",
    "detector",
    "config_hash",
    "analysed_fraction",
    "false_alarms_per_day",
    "dH50_Nms",
    "efficiency_slope",
    "efficiency_max",
    "altitude_km",
    "inclination_deg",
    "epoch_year",
    "spacecraft_file",
    "attitude",
    "run_id",
)
_TEXT = ("spacecraft", "day", "detector", "config_hash", "spacecraft_file", "attitude", "run_id")
ATTITUDES = ("orbit", "unknown")  # body axes = orbit axes (nadir pointing), or not known

_metadata = sa.MetaData()
exposure_table = sa.Table(
    "exposure",
    _metadata,
    sa.Column("spacecraft", sa.String(200), primary_key=True),
    sa.Column("day", sa.String(10), primary_key=True),
    sa.Column("detector", sa.String(200), primary_key=True),
    sa.Column("config_hash", sa.String(64), primary_key=True),
    *[
        sa.Column(name, sa.Float, nullable=False)
        for name in EXPOSURE_COLUMNS
        if name not in _TEXT and name not in ("epoch_year",)
    ],
    sa.Column("epoch_year", sa.Float, nullable=True),
    sa.Column("spacecraft_file", sa.Text, nullable=False),
    sa.Column("attitude", sa.String(16), nullable=False),
    sa.Column("run_id", sa.String(64), nullable=True),
)

#: Spacecraft descriptions (TOML text) the exposure rows name in their ``spacecraft_file`` column, so that a
#: catalog carries the strike geometry with its exposure and no row depends on a path on one machine.
spacecraft_model_table = sa.Table(
    "spacecraft_models",
    _metadata,
    sa.Column("model", sa.String(200), primary_key=True),
    sa.Column("sha256", sa.String(64), nullable=False),
    sa.Column("toml", sa.Text, nullable=False),
)


@dataclass(frozen=True)
class EfficiencyCurve:
    """Detection efficiency against |ΔH|: ε(x) = ε_max / (1 + exp(-k (ln x - ln x50)))."""

    dH50_Nms: float  # [N·m·s] size detected half the time (relative to the plateau)
    slope: float  # [-] logistic slope k in ln|ΔH|
    max_efficiency: float = 1.0  # [-] plateau ε_max

    def __post_init__(self) -> None:
        if not (math.isfinite(self.dH50_Nms) and self.dH50_Nms > 0):
            raise ConfigError(f"efficiency dH50 must be positive, got {self.dH50_Nms!r}", key="dH50_Nms")
        if not (math.isfinite(self.slope) and self.slope > 0):
            raise ConfigError(f"efficiency slope must be positive, got {self.slope!r}", key="efficiency_slope")
        if not (0.0 < self.max_efficiency <= 1.0):
            raise ConfigError(
                f"efficiency plateau must be in (0, 1], got {self.max_efficiency!r}", key="efficiency_max"
            )

    def __call__(self, dH_Nms: ArrayLike) -> NDArray[np.float64]:
        return logistic_efficiency(dH_Nms, self.dH50_Nms, self.slope, self.max_efficiency)

    @property
    def dH90_Nms(self) -> float:
        """|ΔH| found 90 % of the time (relative to the plateau ε_max)."""
        return self.dH50_Nms * math.exp(math.log(9.0) / self.slope)

    @classmethod
    def from_dH90(cls, dH90_Nms: float, slope: float = 4.0) -> EfficiencyCurve:
        """The curve with a given ΔH90 and slope (when only ΔH90 was measured)."""
        return cls(dH90_Nms * math.exp(-math.log(9.0) / slope), slope)


def logistic_efficiency(
    dH_Nms: ArrayLike, dH50_Nms: ArrayLike, slope: ArrayLike, max_efficiency: ArrayLike = 1.0
) -> NDArray[np.float64]:
    """ε(x) for arrays of curves (broadcasting); zero at x <= 0."""
    x = np.asarray(dH_Nms, dtype=np.float64)
    with np.errstate(divide="ignore"):
        z = np.asarray(slope) * (np.log(np.maximum(x, 1e-300)) - np.log(np.asarray(dH50_Nms)))
    return np.asarray(np.asarray(max_efficiency) / (1.0 + np.exp(-np.clip(z, -700, 700))), dtype=np.float64)


def fit_efficiency(dH_Nms: ArrayLike, found: ArrayLike, *, fit_plateau: bool = False) -> EfficiencyCurve:
    """Maximum-likelihood logistic efficiency from injection-recovery outcomes (Bernoulli per injection).

    Args:
        dH_Nms: injected |ΔH| per injection [N·m·s].
        found: whether each injection was recovered.
        fit_plateau: also fit ε_max (otherwise 1).
    """
    x = np.log(np.asarray(dH_Nms, dtype=np.float64))
    y = np.asarray(found, dtype=bool)
    if x.size != y.size or x.size < 3 or not np.all(np.isfinite(x)):
        raise InputError("efficiency fit needs at least 3 injections with positive finite sizes")
    if y.all() or not y.any():
        raise InputError(
            f"efficiency fit: {'all' if y.all() else 'no'} injections were recovered; inject "
            "sizes that bracket the detection threshold"
        )

    def nll(p: NDArray[np.float64]) -> float:
        emax = 1.0 / (1.0 + math.exp(-p[2])) if fit_plateau else 1.0
        pr = emax / (1.0 + np.exp(-np.clip(math.exp(p[1]) * (x - p[0]), -700, 700)))
        pr = np.clip(pr, 1e-12, 1 - 1e-12)
        return -float(np.sum(np.where(y, np.log(pr), np.log1p(-pr))))

    start = np.array([float(np.median(x)), math.log(4.0), 4.0])
    res = minimize(nll, start, method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-9, "maxiter": 4000})
    emax = 1.0 / (1.0 + math.exp(-res.x[2])) if fit_plateau else 1.0
    return EfficiencyCurve(float(math.exp(res.x[0])), float(math.exp(res.x[1])), float(emax))


def efficiency_per_day(
    injections: pd.DataFrame,
    days: Sequence[str],
    *,
    source: str = "recovery table",
    false_alarms_per_day: float | None = None,
) -> dict[str, EfficiencyCurve]:
    """Efficiency curve per day from an injection-recovery table (``dH_Nms``, ``found``, optional ``day``).

    Each day with injections that bracket the threshold gets its own fit (plateau included); a day
    without (no injections, or all or none recovered) gets the fit of all days pooled. A table that
    states the budget it was made at (``false_alarms_per_day``, written by ``inject attitude
    --recovery``) is refused for a detection run at another budget: its efficiency was measured at
    another threshold, and the flux inferred from it would be biased.
    """
    for col in ("dH_Nms", "found"):
        if col not in injections.columns:
            raise InputError(f"{source}: no column {col!r} (expected dH_Nms, found[, day])")
    if false_alarms_per_day is not None and "false_alarms_per_day" in injections.columns:
        stated = pd.to_numeric(injections["false_alarms_per_day"], errors="coerce")
        if not (stated > 0).all():
            row = int(np.flatnonzero(~(stated > 0).to_numpy())[0]) + 2  # the header is line 1
            raise InputError("not a positive rate", file=source, line=row, column="false_alarms_per_day")
        made = stated.unique()
        if any(not math.isclose(float(m), false_alarms_per_day, rel_tol=1e-6) for m in made):
            raise InputError(
                f"{source}: injections recovered at {', '.join(f'{m:g}' for m in made)} false alarms/day, "
                f"the detection ran at {false_alarms_per_day:g}/day: rerun `inject attitude --recovery` at "
                f"--false-alarms {false_alarms_per_day:g}/day",
                column="false_alarms_per_day",
            )
    found = injections["found"].astype(str).str.lower().isin(("true", "1", "yes"))
    sizes = pd.to_numeric(injections["dH_Nms"], errors="coerce").to_numpy()
    pooled = fit_efficiency(sizes, found.to_numpy(), fit_plateau=True)
    out: dict[str, EfficiencyCurve] = {}
    for day in days:
        out[day] = pooled
        if "day" in injections.columns:
            sel = (injections["day"].astype(str) == day).to_numpy()
            try:
                out[day] = fit_efficiency(sizes[sel], found.to_numpy()[sel], fit_plateau=True)
            except InputError:
                pass  # too few or unbracketed injections on this day: the pooled curve
    return out


def exposure_frame(rows: Sequence[dict[str, object]] | pd.DataFrame) -> pd.DataFrame:
    """Check and coerce exposure rows to :data:`EXPOSURE_COLUMNS` (one-line error naming row and column)."""
    frame = pd.DataFrame(rows).copy()
    defaults: dict[str, Any] = {"efficiency_max": 1.0, "epoch_year": float("nan"), "attitude": "unknown"}
    defaults.update({"detector": "", "config_hash": "", "spacecraft_file": "", "run_id": ""})
    for name, value in defaults.items():
        if name not in frame.columns:
            frame[name] = value
    missing = [c for c in EXPOSURE_COLUMNS if c not in frame.columns]
    if missing:
        raise InputError(f"exposure lacks columns {missing}")
    frame = frame.loc[:, list(EXPOSURE_COLUMNS)]
    for name in EXPOSURE_COLUMNS:
        if name in _TEXT:
            frame[name] = frame[name].fillna("").astype(str)
        else:
            frame[name] = pd.to_numeric(frame[name], errors="coerce").astype("float64")
    checks = (
        ("analysed_fraction", lambda v: (v >= 0) & (v <= 1), "must be in [0, 1]"),
        ("false_alarms_per_day", lambda v: v >= 0, "must be >= 0"),
        ("dH50_Nms", lambda v: v > 0, "must be > 0"),
        ("efficiency_slope", lambda v: v > 0, "must be > 0"),
        ("efficiency_max", lambda v: (v > 0) & (v <= 1), "must be in (0, 1]"),
        ("altitude_km", lambda v: v > 100, "must be above 100 km"),
        ("inclination_deg", lambda v: (v >= 0) & (v <= 180), "must be in [0, 180]"),
    )
    for name, ok, reason in checks:
        bad = ~ok(frame[name].to_numpy())
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"exposure row {i + 1}, column {name}: {frame[name].iloc[i]!r} {reason}")
    bad_att = ~frame["attitude"].isin(ATTITUDES)
    if bad_att.any():
        i = int(np.flatnonzero(bad_att.to_numpy())[0])
        raise InputError(f"exposure row {i + 1}, column attitude: {frame['attitude'].iloc[i]!r} not in {ATTITUDES}")
    try:
        pd.to_datetime(frame["day"], format="%Y-%m-%d")
    except ValueError as exc:
        raise InputError(f"exposure column day: {exc}") from None
    if frame.duplicated(["spacecraft", "day", "detector", "config_hash"]).any():
        raise InputError("exposure has duplicated (spacecraft, day, detector, config_hash) rows")
    return frame.reset_index(drop=True)


def store_exposure(catalog: Catalog, rows: pd.DataFrame) -> int:
    """Write exposure rows into the catalog's ``exposure`` table (replacing rows with the same key)."""
    frame = exposure_frame(rows)
    records: list[dict[str, Any]] = [
        {str(k): (None if isinstance(v, float) and math.isnan(v) else v) for k, v in rec.items()}
        for rec in frame.to_dict("records")
    ]
    with catalog.engine.begin() as conn:
        _metadata.create_all(conn)
        t = exposure_table
        if records:  # one executemany of the keyed delete: a statement per row costs ~1 ms (365 000 rows: minutes)
            conn.execute(
                t.delete().where(
                    (t.c.spacecraft == sa.bindparam("k_spacecraft"))
                    & (t.c.day == sa.bindparam("k_day"))
                    & (t.c.detector == sa.bindparam("k_detector"))
                    & (t.c.config_hash == sa.bindparam("k_config_hash"))
                ),
                [{f"k_{k}": rec[k] for k in ("spacecraft", "day", "detector", "config_hash")} for rec in records],
            )
            conn.execute(t.insert(), records)
    return len(records)


def load_exposure(catalog: Catalog, spacecraft: Sequence[str] = ()) -> pd.DataFrame:
    """Exposure rows of a catalog (optionally of some spacecraft); empty frame when it has none."""
    if "exposure" not in sa.inspect(catalog.engine).get_table_names():
        return exposure_frame(pd.DataFrame(columns=list(EXPOSURE_COLUMNS)))
    query = sa.select(exposure_table)
    if spacecraft:
        query = query.where(exposure_table.c.spacecraft.in_(list(spacecraft)))
    with catalog.engine.connect() as conn:
        rows = conn.execute(query.order_by(exposure_table.c.spacecraft, exposure_table.c.day)).all()
    names = [c.name for c in exposure_table.columns]
    # plain tuples: a frame from row mappings (or Row objects) costs 20-60 µs a row, 365 000 rows 7-20 s
    return exposure_frame(pd.DataFrame([tuple(r) for r in rows], columns=names).loc[:, list(EXPOSURE_COLUMNS)])


def exposure_years(exposure: pd.DataFrame, dH_Nms: ArrayLike) -> NDArray[np.float64]:
    """Efficiency-weighted exposure [years] at each |ΔH|: Σ_days f_d ε_d(x) / 365.25 (the flux's divisor)."""
    x = np.asarray(dH_Nms, dtype=np.float64)
    if len(exposure) == 0:
        return np.zeros(x.shape)
    eff = logistic_efficiency(
        x[None, :],
        exposure["dH50_Nms"].to_numpy()[:, None],
        exposure["efficiency_slope"].to_numpy()[:, None],
        exposure["efficiency_max"].to_numpy()[:, None],
    )
    return np.asarray(exposure["analysed_fraction"].to_numpy() @ eff / DAYS_PER_YEAR, dtype=np.float64)


def exposure_summary(exposure: pd.DataFrame) -> pd.DataFrame:
    """The exposure table of a report: per spacecraft, days, analysed years, median ΔH90, false alarms."""
    if len(exposure) == 0:
        return pd.DataFrame(
            columns=["spacecraft", "days", "analysed_years", "dH90_median_Nms", "false_alarms_expected"]
        )
    e = exposure.assign(
        dH90=exposure["dH50_Nms"] * np.exp(np.log(9.0) / exposure["efficiency_slope"]),
        fa=exposure["false_alarms_per_day"] * exposure["analysed_fraction"],
    )
    g = e.groupby("spacecraft", sort=True)
    return pd.DataFrame(
        {
            "days": g.size(),
            "analysed_years": g["analysed_fraction"].sum() / DAYS_PER_YEAR,
            "dH90_median_Nms": g["dH90"].median(),
            "false_alarms_expected": g["fa"].sum(),
            "altitude_km": g["altitude_km"].first(),
            "inclination_deg": g["inclination_deg"].first(),
        }
    ).reset_index()


def store_spacecraft_model(catalog: Catalog, model: str, path: str | Path) -> str:
    """Store a spacecraft TOML (validated) in the catalog under ``model`` (a spacecraft's name or pseudonym,
    which exposure rows then give as their ``spacecraft_file``); re-storing a name replaces its text."""
    if not model:
        raise ConfigError("a spacecraft model needs a non-empty name", key="model")
    load_spacecraft(path)  # validate first: a clear error naming the file and key
    text = Path(path).read_text(encoding="utf-8")
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    t = spacecraft_model_table
    with catalog.engine.begin() as conn:
        _metadata.create_all(conn)
        conn.execute(t.delete().where(t.c.model == model))
        conn.execute(t.insert(), [{"model": model, "sha256": digest, "toml": text}])
    return model


def load_spacecraft_models(catalog: Catalog) -> dict[str, Spacecraft]:
    """The spacecraft descriptions stored in a catalog, by model name (empty when it holds none)."""
    if "spacecraft_models" not in sa.inspect(catalog.engine).get_table_names():
        return {}
    with catalog.engine.connect() as conn:
        rows = conn.execute(sa.select(spacecraft_model_table)).mappings().all()
    out: dict[str, Spacecraft] = {}
    for row in rows:
        source = f"{catalog.name}#spacecraft_models/{row['model']}"
        try:
            data = tomllib.loads(str(row["toml"]))
        except tomllib.TOMLDecodeError as exc:
            raise ConfigError(f"stored spacecraft model is not valid TOML: {exc}", file=source) from None
        out[str(row["model"])] = spacecraft_from_dict(data, source=source)
    return out


def spacecraft_model_digests(catalog: Catalog) -> dict[str, str]:
    """SHA-256 of each stored spacecraft description's TOML text, by model name (empty when none)."""
    if "spacecraft_models" not in sa.inspect(catalog.engine).get_table_names():
        return {}
    t = spacecraft_model_table
    with catalog.engine.connect() as conn:
        rows = conn.execute(sa.select(t.c.model, t.c.sha256)).all()
    return {str(m): str(h) for m, h in rows}


def share_identical_models(exposure: pd.DataFrame, digests: dict[str, str]) -> pd.DataFrame:
    """The exposure with every ``spacecraft_file`` that names a stored description replaced by the first name
    (sorted) holding the same TOML text, so that spacecraft sharing a model share one forward-model template
    (the cost of an inference then grows with the number of distinct models and orbits, not of names)."""
    first: dict[str, str] = {}
    canonical = {name: first.setdefault(digest, name) for name, digest in sorted(digests.items())}
    if all(k == v for k, v in canonical.items()):
        return exposure
    return exposure.assign(spacecraft_file=exposure["spacecraft_file"].map(lambda n: canonical.get(n, n)))


#: Columns of a per-day exposure table (``abrupt flux exposure --table``); ``day`` and ``analysed_fraction``
#: are required, the others override the command's options day by day.
DAY_TABLE_COLUMNS: tuple[str, ...] = (
    "day",
    "analysed_fraction",
    "dH50_Nms",
    "dH90_Nms",
    "efficiency_slope",
    "efficiency_max",
    "false_alarms_per_day",
    "altitude_km",
    "inclination_deg",
    "epoch_year",
    "attitude",
)
_DAY_TABLE_RANGES: dict[str, tuple[float, float, str]] = {  # (low, high, reason): low < v <= high unless noted
    "analysed_fraction": (0.0, 1.0, "must be in [0, 1]"),
    "dH50_Nms": (0.0, math.inf, "must be > 0"),
    "dH90_Nms": (0.0, math.inf, "must be > 0"),
    "efficiency_slope": (0.0, math.inf, "must be > 0"),
    "efficiency_max": (0.0, 1.0, "must be in (0, 1]"),
    "false_alarms_per_day": (0.0, math.inf, "must be >= 0"),
    "altitude_km": (100.0, 384_400.0, "must be an Earth orbit's: above 100 km, below the Moon's distance (384 400 km)"),
    "inclination_deg": (0.0, 180.0, "must be in [0, 180]"),
    "epoch_year": (1957.0, 2200.0, "must be a year"),
}


def read_day_table(path: str | Path) -> pd.DataFrame:
    """Read a per-day exposure table (CSV, columns :data:`DAY_TABLE_COLUMNS`): each day's analysed fraction,
    efficiency (``dH50_Nms`` and ``efficiency_slope``, or ``dH90_Nms`` with an optional slope, default 4),
    false-alarm rate and orbit. Columns absent from the file come from the command's options. Every bad
    cell (not a number, out of range, a day that is not YYYY-MM-DD or given twice, an unknown column, both
    dH50 and dH90 on one row) raises :class:`InputError` naming file, line and column."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", file=path) from None
    except UnicodeDecodeError:
        raise InputError("not UTF-8 text", file=path) from None
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines()) if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise InputError("empty day table (no header)", file=path)
    header_line, header = lines[0]
    names = [h.strip() for h in next(csv.reader([header]))]
    unknown = [n for n in names if n not in DAY_TABLE_COLUMNS]
    if unknown:
        raise InputError(
            f"unknown column(s) {unknown}; expected some of {list(DAY_TABLE_COLUMNS)}", file=path, line=header_line
        )
    for col in ("day", "analysed_fraction"):
        if col not in names:
            raise InputError(f"missing column {col!r}", file=path, line=header_line)
    rows: list[dict[str, Any]] = []
    seen: dict[str, int] = {}
    for line_no, row_text in lines[1:]:
        values = [v.strip() for v in next(csv.reader([row_text]))]
        if len(values) != len(names):
            raise InputError(f"expected {len(names)} fields, got {len(values)}", file=path, line=line_no)
        cells = dict(zip(names, values, strict=True))
        row: dict[str, Any] = {}
        try:
            day = pd.Timestamp(dt.date.fromisoformat(cells["day"])).strftime("%Y-%m-%d")
        except ValueError:
            raise InputError(
                f"{cells['day']!r} is not a day YYYY-MM-DD", file=path, line=line_no, column="day"
            ) from None
        if day in seen:
            raise InputError(f"day {day} also on line {seen[day]}", file=path, line=line_no, column="day")
        seen[day] = line_no
        row["day"] = day
        for col, (low, high, reason) in _DAY_TABLE_RANGES.items():
            if col not in cells or cells[col] == "":
                continue
            try:
                value = float(cells[col])
            except ValueError:
                raise InputError(f"not a number: {cells[col]!r}", file=path, line=line_no, column=col) from None
            inclusive_low = col in ("analysed_fraction", "false_alarms_per_day", "inclination_deg")
            if not (math.isfinite(value) and (value >= low if inclusive_low else value > low) and value <= high):
                raise InputError(f"{value!r} {reason}", file=path, line=line_no, column=col)
            row[col] = value
        if "dH50_Nms" in row and "dH90_Nms" in row:
            raise InputError("give dH50_Nms or dH90_Nms, not both", file=path, line=line_no, column="dH90_Nms")
        if "dH90_Nms" in row:
            curve = EfficiencyCurve.from_dH90(row.pop("dH90_Nms"), row.get("efficiency_slope", 4.0))
            row["dH50_Nms"], row["efficiency_slope"] = curve.dH50_Nms, curve.slope
        elif "efficiency_slope" in row and "dH50_Nms" not in row:
            raise InputError("a slope without dH50_Nms or dH90_Nms", file=path, line=line_no, column="efficiency_slope")
        if cells.get("attitude", ""):
            if cells["attitude"] not in ATTITUDES:
                raise InputError(
                    f"{cells['attitude']!r} not in {ATTITUDES}", file=path, line=line_no, column="attitude"
                )
            row["attitude"] = cells["attitude"]
        rows.append(row)
    if not rows:
        raise InputError("empty day table (header but no rows)", file=path)
    return pd.DataFrame(rows)


def day_range(first: str, last: str) -> list[str]:
    """Every day from ``first`` to ``last`` inclusive (YYYY-MM-DD); error when they are not days or reversed."""
    try:
        a, b = dt.date.fromisoformat(first), dt.date.fromisoformat(last)
    except ValueError as exc:
        raise ConfigError(f"date range {first!r} .. {last!r}: {exc} (use YYYY-MM-DD)", key="from/to") from None
    if b < a:
        raise ConfigError(f"date range {first} .. {last} ends before it starts", key="from/to")
    return [str(d.date()) for d in pd.date_range(a, b, freq="D")]
