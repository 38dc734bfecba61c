"""Telemetry archive dumps: long or wide tables (CSV, CSV.gz, Parquet), pseudonymised at the door.

Harris et al. 2025 §3.3 and §3.7: the first thing done to a raw archive export is to replace the
spacecraft name and every mnemonic by the pseudonyms of a decoder file (``real_name,pseudonym``);
nothing downstream of this module ever sees the decoder or a real name. Archiver artifacts are then
removed and counted (they are not data): blank rows, rows with an empty field, placeholder values
(``-999999``, the text ``NaN``), exact duplicate rows. Conflicting duplicates (same time and mnemonic,
different values) and time reversals are reported and resolved by keeping the first value in file
order and sorting by time.

Layouts:

``long``  columns ``time,mnemonic,value`` (the usual archive export);
``wide``  a ``time`` column and one column per mnemonic (empty cells are "no sample").

Times must be ISO-8601 with a zone (``Z`` or ``+00:00``); a time without a zone is an error naming
the line, unless ``assume_utc`` is set (then it is a counted repair).

A real name never appears in a message, a report or a log: a mnemonic missing from the decoder is
counted and named by a short salted hash only (``unknown-3f9a1c``), which an operator holding the
decoder can reproduce with :func:`name_token`.
"""

from __future__ import annotations

import csv
import gzip
import hashlib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from abrupt.errors import ConfigError, InputError

DEFAULT_PLACEHOLDERS: tuple[float, ...] = (-999999.0, 999999.0, -99999.0, -9999999.0)
TIME_NAMES = ("time", "timestamp", "time_utc", "utc", "datetime")


def name_token(real_name: str) -> str:
    """A short hash of a real name, safe to print: ``unknown-<6 hex>`` (SHA-256 with a fixed salt)."""
    return "unknown-" + hashlib.sha256(("abrupt-pseudonym:" + real_name).encode()).hexdigest()[:6]


@dataclass(frozen=True)
class Decoder:
    """Real name → pseudonym, for spacecraft (names without a dot in the pseudonym) and mnemonics.

    The spacecraft of a mnemonic is the part of its pseudonym before the first dot, which must be a
    spacecraft pseudonym of the same decoder (``SC-A.ch01`` belongs to ``SC-A``).
    """

    mnemonics: dict[str, str]
    spacecraft: dict[str, str]
    source: str = "<decoder>"

    @property
    def real_names(self) -> tuple[str, ...]:
        """Every real name of the decoder (what a leak scan looks for)."""
        return tuple(self.mnemonics) + tuple(self.spacecraft)

    def spacecraft_of(self, pseudonym: str) -> str:
        return pseudonym.split(".", 1)[0]


def read_decoder(path: str | Path) -> Decoder:
    """Read a ``real_name,pseudonym`` decoder; an error names the line and the reason."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise InputError(f"cannot read decoder: {exc.strerror}", file=path) from None
    rows = list(csv.reader(text.splitlines()))
    if not rows or [c.strip().lower() for c in rows[0][:2]] != ["real_name", "pseudonym"]:
        raise InputError("expected the header 'real_name,pseudonym'", file=path, line=1)
    mnemonics: dict[str, str] = {}
    spacecraft: dict[str, str] = {}
    seen_pseudo: dict[str, int] = {}
    for i, row in enumerate(rows[1:], start=2):
        if not row or all(not c.strip() for c in row):
            continue
        if len(row) != 2 or not row[0].strip() or not row[1].strip():
            raise InputError("expected two non-empty fields 'real_name,pseudonym'", file=path, line=i)
        real, pseudo = row[0].strip(), row[1].strip()
        if pseudo in seen_pseudo:
            raise InputError(f"pseudonym already used on line {seen_pseudo[pseudo]}", file=path, line=i, column=2)
        seen_pseudo[pseudo] = i
        target = mnemonics if "." in pseudo else spacecraft
        if real in target:
            raise InputError("real name listed twice", file=path, line=i, column=1)
        target[real] = pseudo
    if not mnemonics:
        raise InputError("no mnemonic pseudonyms (pseudonyms of mnemonics contain a dot: 'SC-A.ch01')", file=path)
    known = set(spacecraft.values())
    for pseudo in mnemonics.values():
        sc = pseudo.split(".", 1)[0]
        if sc not in known:
            line = seen_pseudo[pseudo]
            raise InputError(
                f"mnemonic pseudonym {pseudo!r} does not start with a spacecraft pseudonym of this decoder "
                f"({sorted(known)})",
                file=path,
                line=line,
                column=2,
            )
    return Decoder(mnemonics=mnemonics, spacecraft=spacecraft, source=str(path))


@dataclass
class DayReport:
    """What ingest did to one spacecraft-day: rows kept, artifacts removed and anomalies reported."""

    spacecraft: str
    day: str
    rows_kept: int = 0
    removed: Counter[str] = field(default_factory=Counter)
    reported: Counter[str] = field(default_factory=Counter)
    channels: dict[str, int] = field(default_factory=dict)
    sources: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, object]:
        return {
            "spacecraft": self.spacecraft,
            "day": self.day,
            "rows_kept": self.rows_kept,
            "removed": dict(sorted(self.removed.items())),
            "reported": dict(sorted(self.reported.items())),
            "samples_per_channel": dict(sorted(self.channels.items())),
            "sources": self.sources,
        }


@dataclass
class ArchiveChunk:
    """Pseudonymised samples of one archive file (columns spacecraft, mnemonic, time, value) + counts.

    ``file_counts`` are artifacts that cannot be attributed to a day (rows without a valid time).
    """

    samples: pd.DataFrame
    per_day: dict[tuple[str, str], DayReport]
    file_counts: Counter[str]


def pseudonymise_text(text: str, decoder: Decoder) -> str:
    """``text`` with every real name of the decoder replaced by its pseudonym (longest names first)."""
    pairs = sorted({**decoder.spacecraft, **decoder.mnemonics}.items(), key=lambda kv: -len(kv[0]))
    for real, pseudo in pairs:
        if real in text:
            text = text.replace(real, pseudo)
    return text


def _read_raw(path: Path) -> pa.Table:
    name = path.name.lower()
    try:
        if name.endswith(".parquet") or name.endswith(".pq"):
            return pq.read_table(path)
        with open(path, "rb") as fh:
            gz = fh.read(2) == b"\x1f\x8b"
        # Only the empty field is null: the text "NaN" is a placeholder and is counted as such.
        opts = pacsv.ConvertOptions(null_values=[""], strings_can_be_null=True, quoted_strings_can_be_null=True)
        read = pacsv.ReadOptions(block_size=1 << 24)
        parse = pacsv.ParseOptions(ignore_empty_lines=True)
        if gz:
            with pa.CompressedInputStream(pa.OSFile(str(path)), "gzip") as stream:
                return pacsv.read_csv(stream, read_options=read, parse_options=parse, convert_options=opts)
        return pacsv.read_csv(str(path), read_options=read, parse_options=parse, convert_options=opts)
    except pa.ArrowInvalid as exc:
        raise InputError(f"not a readable table: {str(exc).splitlines()[0]}", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot read archive: {exc}", file=path) from None


def _line_of_first(path: Path, predicate_text: str) -> int | None:
    """1-based line of the first line containing ``predicate_text`` (error path only)."""
    opener = gzip.open if path.read_bytes()[:2] == b"\x1f\x8b" else open
    with opener(path, "rt", encoding="utf-8", errors="replace") as fh:
        for i, line in enumerate(fh, start=1):
            if predicate_text in line:
                return i
    return None


def _long_from_wide(table: pa.Table, time_col: str) -> pa.Table:
    parts = []
    for c in table.column_names:
        if c == time_col:
            continue
        col = table.column(c)
        parts.append(
            pa.table(
                {
                    "time": table.column(time_col),
                    "mnemonic": pa.array(np.full(table.num_rows, c, dtype=object), pa.string()),
                    "value": col.cast(pa.string()) if col.type != pa.string() else col,
                }
            )
        )
    return pa.concat_tables(parts) if parts else pa.table({"time": [], "mnemonic": [], "value": []})


def _parse_times(times: pa.ChunkedArray, path: Path, assume_utc: bool, counts: Counter[str]) -> pa.ChunkedArray:
    if pa.types.is_timestamp(times.type):
        if times.type.tz is None:
            if not assume_utc:
                raise InputError(
                    "times have no time zone; give times in UTC with 'Z' or pass --assume-utc",
                    file=path,
                    column="time",
                )
            counts["times without zone read as UTC"] += len(times) - times.null_count
            return pc.assume_timezone(times.cast(pa.timestamp("ns")), "UTC")
        return times.cast(pa.timestamp("ns", tz="UTC"))
    text = times.cast(pa.string())
    try:
        return text.cast(pa.timestamp("ns", tz="UTC"))
    except pa.ArrowInvalid as exc:
        msg = str(exc)
        bad = msg.split("'")[1] if "'" in msg else ""
        if "zone offset" in msg:
            if not assume_utc:
                line = _line_of_first(path, bad) if bad else None
                raise InputError(
                    f"time {bad!r} has no time zone; give times in UTC with 'Z' or pass --assume-utc",
                    file=path,
                    line=line,
                    column="time",
                ) from None
            # Mixed or zone-less: parse each kind separately.
            has_zone = pc.match_substring_regex(text, r"(Z|[+-]\d\d:?\d\d)$")
            has_zone = pc.fill_null(has_zone, False)
            counts["times without zone read as UTC"] += int(pc.sum(pc.invert(has_zone)).as_py() or 0) - text.null_count
            fixed = pc.if_else(has_zone, text, pc.binary_join_element_wise(text, "Z", ""))
            return fixed.cast(pa.timestamp("ns", tz="UTC"))
        # Unparseable times: skip and count them, one bad record is not fatal.
        parsed = pd.to_datetime(pd.Series(text.to_pandas(), dtype=object), utc=True, errors="coerce", format="ISO8601")
        bad_n = int(parsed.isna().sum()) - text.null_count
        counts["unparseable times"] += bad_n
        return pa.chunked_array([pa.array(parsed, pa.timestamp("ns", tz="UTC"))])


def _parse_values(values: pa.ChunkedArray) -> tuple[np.ndarray, int]:
    """Values as float64 (NaN for empty or unparseable); returns the number of unparseable texts."""
    if pa.types.is_floating(values.type) or pa.types.is_integer(values.type) or pa.types.is_boolean(values.type):
        return np.asarray(values.cast(pa.float64()).to_numpy(zero_copy_only=False), dtype=np.float64), 0
    try:
        arr = values.cast(pa.float64())
        return np.asarray(arr.to_numpy(zero_copy_only=False), dtype=np.float64), 0
    except pa.ArrowInvalid:
        s = pd.Series(values.to_pandas(), dtype=object)
        num = pd.to_numeric(s, errors="coerce")
        bad = int((num.isna() & s.notna() & (s.str.strip().str.lower() != "nan")).sum())
        return np.asarray(num, dtype=np.float64), bad


def read_archive(
    path: str | Path,
    decoder: Decoder,
    *,
    layout: str = "auto",
    placeholders: tuple[float, ...] = DEFAULT_PLACEHOLDERS,
    assume_utc: bool = False,
) -> ArchiveChunk:
    """Read one archive file, replace real names by pseudonyms and remove archiver artifacts.

    Returns pseudonymised samples (``spacecraft``, ``mnemonic`` pseudonyms, ``time`` UTC, ``value``)
    sorted by spacecraft, mnemonic and time, with per-day counts of everything removed or reported.
    An error message names the file by its pseudonymised name, so it never carries a real name.
    """
    try:
        return _read_archive(path, decoder, layout=layout, placeholders=placeholders, assume_utc=assume_utc)
    except InputError as exc:
        raise InputError(
            pseudonymise_text(exc.reason, decoder),
            file=pseudonymise_text(exc.file or str(path), decoder),
            line=exc.line,
            column=pseudonymise_text(exc.column, decoder) if isinstance(exc.column, str) else exc.column,
        ) from None


def _read_archive(
    path: str | Path,
    decoder: Decoder,
    *,
    layout: str = "auto",
    placeholders: tuple[float, ...] = DEFAULT_PLACEHOLDERS,
    assume_utc: bool = False,
) -> ArchiveChunk:
    """Read one archive file, replace real names by pseudonyms and remove archiver artifacts.

    Returns pseudonymised samples (``spacecraft``, ``mnemonic`` pseudonyms, ``time`` UTC, ``value``)
    sorted by spacecraft, mnemonic and time, with per-day counts of everything removed or reported.
    """
    path = Path(path)
    table = _read_raw(path)
    cols = [c.strip() for c in table.column_names]
    table = table.rename_columns(cols)
    lower = [c.lower() for c in cols]
    time_col = next((cols[i] for i, c in enumerate(lower) if c in TIME_NAMES), None)
    if time_col is None:
        raise InputError(f"no time column (one of {list(TIME_NAMES)})", file=path, line=1)
    is_long = {"mnemonic", "value"} <= set(lower)
    if layout == "long" or (layout == "auto" and is_long):
        if not is_long:
            raise InputError("long layout needs columns time,mnemonic,value", file=path, line=1)
        table = table.select([time_col, cols[lower.index("mnemonic")], cols[lower.index("value")]])
        table = table.rename_columns(["time", "mnemonic", "value"])
    elif layout in ("wide", "auto"):
        table = _long_from_wide(table, time_col)
    else:
        raise ConfigError(f"layout must be 'auto', 'long' or 'wide', got {layout!r}", key="layout")

    counts: Counter[str] = Counter()
    n0 = table.num_rows
    # Rows that are entirely empty (",,") are blank-line artifacts.
    mnem = table.column("mnemonic")
    all_empty = pc.and_(pc.is_null(table.column("time")), pc.is_null(mnem))
    all_empty = pc.and_(all_empty, pc.is_null(table.column("value")))
    n_blank = int(pc.sum(all_empty).as_py() or 0)
    if n_blank:
        table = table.filter(pc.invert(all_empty))
    times = _parse_times(table.column("time"), path, assume_utc, counts)
    values, bad_values = _parse_values(table.column("value"))
    value_null = np.asarray(table.column("value").is_null().to_numpy(zero_copy_only=False), dtype=bool)
    mnem_arr = table.column("mnemonic")

    # Pseudonyms at the door: map real mnemonic -> pseudonym through a dictionary encoding.
    enc = mnem_arr.combine_chunks().dictionary_encode() if mnem_arr.num_chunks else pa.array([], pa.string())
    dictionary = enc.dictionary.to_pylist()
    codes = np.asarray(enc.indices.fill_null(-1).to_numpy(zero_copy_only=False), dtype=np.int64)
    pseudo_of_code = [decoder.mnemonics.get(str(name).strip()) for name in dictionary]
    unknown_codes = [i for i, p in enumerate(pseudo_of_code) if p is None]
    known_code = np.array([p is not None for p in pseudo_of_code] + [False], dtype=bool)
    codes_safe = np.where(codes < 0, len(pseudo_of_code), codes)
    row_known = known_code[codes_safe]
    del table, enc, mnem_arr

    t_null = np.asarray(times.is_null().to_numpy(zero_copy_only=False), dtype=bool)
    t_valid = ~t_null
    t_int = np.where(t_valid, np.asarray(times.cast(pa.int64()).fill_null(0).to_numpy(), np.int64), 0)

    no_name = codes < 0
    is_placeholder = np.isin(values, np.asarray(placeholders, dtype=np.float64)) | (np.isnan(values) & ~value_null)
    empty_value = value_null
    # Order of judgement: missing time or name -> empty value -> placeholder -> name not in decoder.
    drop_missing = ~t_valid | no_name
    drop_empty = ~drop_missing & empty_value
    drop_placeholder = ~drop_missing & ~drop_empty & is_placeholder
    drop_unknown = ~drop_missing & ~drop_empty & ~drop_placeholder & ~row_known
    keep = ~(drop_missing | drop_empty | drop_placeholder | drop_unknown)
    counts["rows read"] = n0
    counts["blank rows"] += n_blank
    if bad_values:
        counts["unparseable values"] += bad_values
    unknown_names: Counter[str] = Counter()
    for c in unknown_codes:
        n_c = int(np.count_nonzero((codes == c) & ~drop_missing & ~drop_empty & ~drop_placeholder))
        if n_c:
            unknown_names[name_token(str(dictionary[c]))] += n_c

    pseudo_arr = np.array([p if p is not None else "" for p in pseudo_of_code] + [""], dtype=object)
    day_ns = 86_400 * 1_000_000_000
    day_idx = np.where(t_valid, t_int // day_ns, -1)
    sc_pseudo = np.array([decoder.spacecraft_of(p) if p else "" for p in pseudo_arr], dtype=object)

    per_day: dict[tuple[str, str], DayReport] = {}

    def report(sc: str, d: int) -> DayReport:
        key = (sc, str(np.datetime64(int(d), "D")))
        if key not in per_day:
            per_day[key] = DayReport(spacecraft=key[0], day=key[1], sources=[pseudonymise_text(path.name, decoder)])
        return per_day[key]

    # Per-day counts of artifacts that have a day and a spacecraft.
    for label, mask in (
        ("empty values", drop_empty),
        ("placeholder values", drop_placeholder),
        ("names not in the decoder", drop_unknown),
    ):
        sel = mask & t_valid
        if not sel.any():
            continue
        sc_rows = sc_pseudo[codes_safe[sel]]
        days = day_idx[sel]
        for (sc, d), n in Counter(zip(sc_rows, days, strict=True)).items():
            report(sc or "unattributed", d).removed[label] += n
    missing_time_rows = int(np.count_nonzero(~t_valid))
    if missing_time_rows:
        counts["rows without a time"] += missing_time_rows
    no_name_rows = int(np.count_nonzero(no_name & t_valid))
    if no_name_rows:
        counts["rows without a mnemonic"] += no_name_rows
    if unknown_names:
        counts.update({f"rows of a name not in the decoder ({k})": v for k, v in unknown_names.items()})

    idx = np.flatnonzero(keep)
    frame = pd.DataFrame(
        {
            "spacecraft": pd.Categorical(sc_pseudo[codes_safe[idx]]),
            "mnemonic": pd.Categorical(pseudo_arr[codes_safe[idx]]),
            "time_ns": t_int[idx],
            "value": values[idx],
            "order": idx,
        }
    )
    frame = _dedupe(frame, per_day, report)
    for (sc, d), grp in frame.groupby(["spacecraft", frame["time_ns"] // day_ns], observed=True, sort=False):
        r = report(str(sc), int(d))  # type: ignore[call-overload]
        r.rows_kept += len(grp)
        for m, n in grp["mnemonic"].value_counts().items():
            if n:
                r.channels[str(m)] = r.channels.get(str(m), 0) + int(n)
    frame["time"] = pd.to_datetime(frame.pop("time_ns"), utc=True)
    frame = frame.drop(columns="order")
    return ArchiveChunk(samples=frame.reset_index(drop=True), per_day=per_day, file_counts=counts)


def _dedupe(frame: pd.DataFrame, per_day: dict[tuple[str, str], DayReport], report: object) -> pd.DataFrame:
    """Remove exact duplicates, report conflicting duplicates and time reversals; sort by time."""
    day_ns = 86_400 * 1_000_000_000
    rep = report  # callable (sc, day_index) -> DayReport
    codes = frame["mnemonic"].cat.codes.to_numpy()
    sc_codes = frame["spacecraft"].cat.codes.to_numpy()
    t = frame["time_ns"].to_numpy()
    # Time reversals: within one mnemonic in file order, a time earlier than the previous one.
    key = sc_codes.astype(np.int64) * 1_000_003 + codes
    order_file = np.lexsort((frame["order"].to_numpy(), key))
    k_sorted = key[order_file]
    t_sorted = t[order_file]
    rev = np.zeros(len(t), bool)
    if len(t) > 1:
        same = k_sorted[1:] == k_sorted[:-1]
        back = same & (t_sorted[1:] < t_sorted[:-1])
        rev[order_file[1:][back]] = True
    _count(frame, rev, "time reversals (sorted)", rep, day_ns, reported=True)
    # Sort by key, time, file order (stable).
    order = np.lexsort((frame["order"].to_numpy(), t, key))
    frame = frame.iloc[order].reset_index(drop=True)
    key = key[order]
    t = t[order]
    v = frame["value"].to_numpy()
    if len(t) > 1:
        same_t = np.concatenate([[False], (key[1:] == key[:-1]) & (t[1:] == t[:-1])])
        same_v = np.concatenate([[False], v[1:] == v[:-1]])
        exact = same_t & same_v
        # A conflicting duplicate differs from the first row of its (key, time) group.
        first_of_group = ~same_t
        group_first_value = v[np.maximum.accumulate(np.where(first_of_group, np.arange(len(v)), 0))]
        conflict = same_t & (v != group_first_value)
        exact = same_t & ~conflict
    else:
        exact = conflict = np.zeros(len(t), bool)
    _count(frame, exact, "exact duplicate rows", rep, day_ns, reported=False)
    _count(frame, conflict, "conflicting duplicates (first value kept)", rep, day_ns, reported=True)
    return frame.loc[~(exact | conflict)].reset_index(drop=True)


def _count(frame: pd.DataFrame, mask: np.ndarray, label: str, rep: object, day_ns: int, *, reported: bool) -> None:
    if not mask.any():
        return
    sub = frame.loc[mask]
    for (sc, d), n in Counter(zip(sub["spacecraft"].astype(str), sub["time_ns"] // day_ns, strict=True)).items():
        r = rep(sc, int(d))  # type: ignore[operator]
        (r.reported if reported else r.removed)[label] += n
