"""Telemetry archive dumps: long or wide tables (CSV, CSV.gz, Parquet), pseudonymised at the door.

Harris et al. 2025 §3.3 and §3.7: the first thing done to a raw archive export is to replace the
spacecraft name and every mnemonic by the pseudonyms of a decoder file (``real_name,pseudonym``);
nothing downstream of this module ever sees the decoder or a real name. Archiver artifacts are then
removed and counted (they are not data): blank rows, rows with an empty field, placeholder values
(``-999999``, the text ``NaN``), infinite or absurd values (``inf``, ``1e300``: beyond 1e20, above
any 64-bit counter; counter "infinite or absurd values (|v| > 1e20)"), rows dated more than a day after
today (counter "rows dated after today"), exact duplicate rows.
Conflicting duplicates (same time and mnemonic, different values) and time reversals are reported
and resolved by keeping the first value in file order and sorting by time.

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
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from abrupt.errors import ConfigError, InputError
from abrupt.readers.compression import read_bytes
from abrupt.readers.text import check_column_count

DEFAULT_PLACEHOLDERS: tuple[float, ...] = (-999999.0, 999999.0, -99999.0, -9999999.0)
# Beyond any telemetry value: above the largest 64-bit counter (1.8e19); inf and 1e300 are corruption.
MAX_ABS_VALUE = 1e20
ARCHIVE_ABSURD = "infinite or absurd values (|v| > 1e20)"
ARCHIVE_CUT_LINE = "last line cut (no line end, fields missing: skipped)"
ARCHIVE_FUTURE = "rows dated after today (telemetry is recorded, not predicted)"
FUTURE_MARGIN_NS = 86_400 * 10**9  # a day of clock and time-zone slack before a time counts as in the future


def _latest_time_ns() -> int:
    """The latest sample time (ns since 1970, UTC) an archive may hold: now plus a day."""
    return int(np.datetime64("now", "ns").astype(np.int64)) + FUTURE_MARGIN_NS


TIME_NAMES = ("time", "timestamp", "time_utc", "utc", "datetime")


MAX_LISTED_UNKNOWN = 5  # unknown names listed one by one; more are summarised in one count


def _unknown_name_counts(unknown_names: Counter[str], n_names: int) -> dict[str, int]:
    """Rows of names not in the decoder, by name token; more than :data:`MAX_LISTED_UNKNOWN` names are one
    count naming how many names and the first few tokens (100 000 names must not make a 5 MB line)."""
    if len(unknown_names) <= MAX_LISTED_UNKNOWN:
        return {f"rows of a name not in the decoder ({k})": v for k, v in unknown_names.items()}
    first = ", ".join(k for k, _ in unknown_names.most_common(MAX_LISTED_UNKNOWN))
    label = f"rows of {n_names} names not in the decoder (most rows: {first}, ...)"
    return {label: sum(unknown_names.values())}


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


def _check_pseudonyms_hide(pseudonym_of: dict[str, str], line_of: dict[str, int], path: Path) -> None:
    """Refuse a pseudonym that contains (or is) a real name of the decoder, whatever the case
    (``KESTREL2-anon``, ``kestrel2``): it would carry that name into the store, its reports and the
    console. Neither name is quoted in the error, which names the lines instead."""
    line_of_real = {real.lower(): line_of[pseudo] for real, pseudo in pseudonym_of.items()}
    pattern = re.compile("|".join(re.escape(r) for r in sorted(line_of_real, key=len, reverse=True)), re.IGNORECASE)
    for pseudo, line in sorted(line_of.items(), key=lambda item: item[1]):
        found = pattern.search(pseudo)
        if found:
            real_line = line_of_real[found.group(0).lower()]
            raise InputError(
                f"the pseudonym contains the real name of line {real_line} (case-insensitive): a pseudonym must not "
                "reveal a real name",
                file=path,
                line=line,
                column=2,
            )
    for pseudo, line in line_of.items():
        if not pseudo.isprintable():
            raise InputError("the pseudonym holds a control character", file=path, line=line, column=2)


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
    _check_pseudonyms_hide({**mnemonics, **spacecraft}, seen_pseudo, path)
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
    """``text`` with every real name of the decoder replaced by its pseudonym, whatever its case
    (``kestrel2_dump.csv`` as well as ``KESTREL2``); the longest name wins where names overlap."""
    by_lower: dict[str, str] = {}
    for real, pseudo in {**decoder.spacecraft, **decoder.mnemonics}.items():
        by_lower.setdefault(real.lower(), pseudo)
    if not by_lower or not text:
        return text
    pattern = re.compile("|".join(re.escape(r) for r in sorted(by_lower, key=len, reverse=True)), re.IGNORECASE)
    return pattern.sub(lambda m: by_lower[m.group(0).lower()], text)


def _cut_last_line(path: Path, n_fields: int) -> int | None:
    """The byte length of the file without its last line when that line was cut by an interrupted export:
    no line end after it and fewer fields than the header's ``n_fields``; None otherwise (a plain file)."""
    size = path.stat().st_size
    with open(path, "rb") as fh:
        fh.seek(max(0, size - 65536))
        tail = fh.read()
    if not tail or tail.endswith(b"\n"):
        return None
    start = tail.rfind(b"\n") + 1
    if start == 0 or tail[start:].count(b",") + 1 >= n_fields:
        return None
    return size - (len(tail) - start)


def _read_raw(path: Path, counts: Counter[str]) -> pa.Table:
    name = path.name.lower()
    try:
        if name.endswith(".parquet") or name.endswith(".pq"):
            return pq.read_table(path)
        with open(path, "rb") as fh:
            gz = fh.read(2) == b"\x1f\x8b"
        read = pacsv.ReadOptions(block_size=1 << 24)
        parse = pacsv.ParseOptions(ignore_empty_lines=True)
        check_column_count(path)
        header = _header(path, gz)
        cut = None if gz else _cut_last_line(path, len(header))

        def csv_with(opts: pacsv.ConvertOptions) -> pa.Table:
            if gz:
                with pa.CompressedInputStream(pa.OSFile(str(path)), "gzip") as stream:
                    return pacsv.read_csv(stream, read_options=read, parse_options=parse, convert_options=opts)
            if cut is not None:  # the whole lines only, read in place
                whole = pa.BufferReader(pa.memory_map(str(path)).read_buffer(cut))
                return pacsv.read_csv(whole, read_options=read, parse_options=parse, convert_options=opts)
            return pacsv.read_csv(str(path), read_options=read, parse_options=parse, convert_options=opts)

        if cut is not None:
            counts[ARCHIVE_CUT_LINE] += 1
        # Only the empty field is null: the text "NaN" parses as a float NaN and is counted as a placeholder.
        lower = [h.strip().lower() for h in header]
        if len(header) == 3 and lower[0] in TIME_NAMES and lower[1:] == ["mnemonic", "value"]:
            # The usual long export, typed while parsing (UTC times, dictionary-encoded names, float
            # values): no Python strings per row. Anything it cannot type (a time without a zone, an
            # unparseable value) is read again the general way below, which names or counts it.
            typed = pacsv.ConvertOptions(
                column_types={
                    header[0]: pa.timestamp("ns", tz="UTC"),
                    header[1]: pa.dictionary(pa.int32(), pa.string()),
                    header[2]: pa.float64(),
                },
                null_values=[""],
                strings_can_be_null=True,
                quoted_strings_can_be_null=True,
            )
            try:
                return csv_with(typed)
            except pa.ArrowInvalid:
                pass
        return csv_with(
            pacsv.ConvertOptions(null_values=[""], strings_can_be_null=True, quoted_strings_can_be_null=True)
        )
    except pa.ArrowInvalid as exc:
        raise InputError(f"not a readable table: {str(exc).splitlines()[0]}", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot read archive: {exc}", file=path) from None


def _header(path: Path, gz: bool) -> list[str]:
    """Column names of a CSV file's first line ([] if unreadable)."""
    opener = gzip.open if gz else open
    try:
        with opener(path, "rt", encoding="utf-8-sig", errors="replace") as fh:
            return next(csv.reader([fh.readline()]), [])
    except (OSError, EOFError):
        return []


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
    except pa.ArrowInvalid as exc:  # e.g. bytes that are not UTF-8 in a text column
        raise InputError(
            pseudonymise_text(f"unreadable data: {str(exc).splitlines()[0]}", decoder),
            file=pseudonymise_text(str(path), decoder),
        ) from None


DAY_NS = 86_400 * 1_000_000_000


def _refuse_non_utf8(path: Path) -> None:
    """Raise the :class:`InputError` of a text archive that is not UTF-8 (a column the CSV parser left as
    bytes would match no decoder name, and every row would be dropped), naming the first bad byte."""
    raw = read_bytes(path)
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise InputError(
            f"not UTF-8 text (byte 0x{raw[exc.start]:02x}); export the archive as UTF-8",
            file=path,
            line=line,
            column=column,
        ) from None
    raise InputError("a column holds bytes that are not text", file=path)


def _long_table(path: Path, layout: str, counts: Counter[str]) -> pa.Table:
    """The file as a long table ``time, mnemonic, value`` (wide tables are melted)."""
    table = _read_raw(path, counts)
    text = not path.name.lower().endswith((".parquet", ".pq"))
    if text and any(pa.types.is_binary(f.type) or pa.types.is_large_binary(f.type) for f in table.schema):
        _refuse_non_utf8(path)
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
        return table.rename_columns(["time", "mnemonic", "value"])
    if layout in ("wide", "auto"):
        return _long_from_wide(table, time_col)
    raise ConfigError(f"layout must be 'auto', 'long' or 'wide', got {layout!r}", key="layout")


def _mnemonic_codes(mnem_arr: pa.ChunkedArray, decoder: Decoder) -> tuple[list[Any], np.ndarray, list[str | None]]:
    """Pseudonyms at the door: (real names, code of each row (-1: none), pseudonym of each code or None)."""
    if pa.types.is_dictionary(mnem_arr.type):
        enc = mnem_arr.unify_dictionaries().combine_chunks() if mnem_arr.num_chunks else pa.array([], pa.string())
        if not mnem_arr.num_chunks:
            enc = enc.dictionary_encode()
    else:
        enc = mnem_arr.combine_chunks().dictionary_encode() if mnem_arr.num_chunks else pa.array([], pa.string())
    dictionary = enc.dictionary.to_pylist()
    codes = np.asarray(enc.indices.fill_null(-1).to_numpy(zero_copy_only=False), dtype=np.int64)
    return dictionary, codes, [decoder.mnemonics.get(str(name).strip()) for name in dictionary]


class _DayReports:
    """Reports per (spacecraft, day), created on first use in the order they are met."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.per_day: dict[tuple[str, str], DayReport] = {}

    def __call__(self, sc: str, d: int) -> DayReport:
        key = (sc, str(np.datetime64(int(d), "D")))
        if key not in self.per_day:
            self.per_day[key] = DayReport(spacecraft=key[0], day=key[1], sources=[self.source])
        return self.per_day[key]


@dataclass
class _Channels:
    """Kept rows by pseudonymised channel: names sorted, so that channel codes group each spacecraft."""

    names: list[str]
    spacecraft: list[str]
    spacecraft_of: np.ndarray  # channel code -> spacecraft index
    reports: _DayReports

    def count(self, mask: np.ndarray, m: np.ndarray, t: np.ndarray, label: str, *, reported: bool) -> None:
        """Add the rows of ``mask`` (channel codes ``m``, times ``t`` [ns]) under ``label`` per spacecraft-day."""
        if not mask.any():
            return
        pairs = zip(self.spacecraft_of[m[mask]].tolist(), (t[mask] // DAY_NS).tolist(), strict=True)
        for (sc, d), n in Counter(pairs).items():
            r = self.reports(self.spacecraft[sc], d)
            (r.reported if reported else r.removed)[label] += n


def _sort_and_dedupe(
    m_codes: np.ndarray, t_k: np.ndarray, v_k: np.ndarray, ch: _Channels
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sort by (channel, time), reporting time reversals; drop exact duplicates and conflicting ones (first kept)."""
    # Time reversals: within one mnemonic in file order, a time earlier than the previous one.
    order = np.argsort(m_codes, kind="stable")
    k_sorted, t_sorted = m_codes[order], t_k[order]
    back = (k_sorted[1:] == k_sorted[:-1]) & (t_sorted[1:] < t_sorted[:-1])
    if back.any():
        rev = np.zeros(m_codes.size, bool)
        rev[order[1:][back]] = True
        ch.count(rev, m_codes, t_k, "time reversals (sorted)", reported=True)
        order = np.lexsort((t_k, m_codes))  # stable: equal (mnemonic, time) stay in file order
    m_codes, t_k, v_k = m_codes[order], t_k[order], v_k[order]
    del order, k_sorted, t_sorted
    if m_codes.size > 1:
        same_t = np.concatenate([[False], (m_codes[1:] == m_codes[:-1]) & (t_k[1:] == t_k[:-1])])
        first = np.maximum.accumulate(np.where(~same_t, np.arange(m_codes.size), 0))
        conflict = same_t & (v_k != v_k[first])
        exact = same_t & ~conflict
    else:
        exact = conflict = np.zeros(m_codes.size, bool)
    ch.count(exact, m_codes, t_k, "exact duplicate rows", reported=False)
    # A conflicting duplicate differs from the first row of its (mnemonic, time) group.
    ch.count(conflict, m_codes, t_k, "conflicting duplicates (first value kept)", reported=True)
    if exact.any() or conflict.any():
        keep_rows = ~(exact | conflict)
        m_codes, t_k, v_k = m_codes[keep_rows], t_k[keep_rows], v_k[keep_rows]
    return m_codes, t_k, v_k


def _count_kept(m_codes: np.ndarray, t_k: np.ndarray, ch: _Channels) -> None:
    """Rows kept and samples per channel, per spacecraft-day."""
    if not m_codes.size:
        return
    d_k = t_k // DAY_NS
    d_min = int(d_k.min())
    combo = m_codes * (int(d_k.max()) - d_min + 1) + (d_k - d_min)
    uniq, n_rows = np.unique(combo, return_counts=True)
    span = int(d_k.max()) - d_min + 1
    for u, n in zip(uniq.tolist(), n_rows.tolist(), strict=True):
        m, d = divmod(u, span)
        r = ch.reports(ch.spacecraft[ch.spacecraft_of[m]], d + d_min)
        r.rows_kept += n
        name = ch.names[m]
        r.channels[name] = r.channels.get(name, 0) + n


def _samples_frame(m_codes: np.ndarray, t_k: np.ndarray, v_k: np.ndarray, ch: _Channels) -> pd.DataFrame:
    sc_cat: Any
    mn_cat: Any
    if ch.names:
        sc_cat = pd.Categorical.from_codes(
            ch.spacecraft_of[m_codes], categories=pd.Index(ch.spacecraft), validate=False
        )
        mn_cat = pd.Categorical.from_codes(m_codes, categories=pd.Index(ch.names), validate=False)
    else:
        sc_cat = mn_cat = pd.Categorical([])
    return pd.DataFrame(
        {
            "spacecraft": sc_cat,
            "mnemonic": mn_cat,
            "time": pd.Series(t_k.view("datetime64[ns]")).dt.tz_localize("UTC"),
            "value": v_k,
        }
    )


def _read_archive(
    path: str | Path,
    decoder: Decoder,
    *,
    layout: str = "auto",
    placeholders: tuple[float, ...] = DEFAULT_PLACEHOLDERS,
    assume_utc: bool = False,
) -> ArchiveChunk:
    """:func:`read_archive` without the pseudonymisation of error messages."""
    path = Path(path)
    counts: Counter[str] = Counter()
    table = _long_table(path, layout, counts)
    n0 = table.num_rows
    # Rows that are entirely empty (",,") are blank-line artifacts.
    all_empty = pc.and_(pc.is_null(table.column("time")), pc.is_null(table.column("mnemonic")))
    all_empty = pc.and_(all_empty, pc.is_null(table.column("value")))
    n_blank = int(pc.sum(all_empty).as_py() or 0)
    if n_blank:
        table = table.filter(pc.invert(all_empty))
    times = _parse_times(table.column("time"), path, assume_utc, counts)
    values, bad_values = _parse_values(table.column("value"))
    value_null = np.asarray(table.column("value").is_null().to_numpy(zero_copy_only=False), dtype=bool)
    dictionary, codes, pseudo_of_code = _mnemonic_codes(table.column("mnemonic"), decoder)
    unknown_codes = [i for i, p in enumerate(pseudo_of_code) if p is None]
    known_code = np.array([p is not None for p in pseudo_of_code] + [False], dtype=bool)
    codes_safe = np.where(codes < 0, len(pseudo_of_code), codes)
    row_known = known_code[codes_safe]
    del table

    t_valid = ~np.asarray(times.is_null().to_numpy(zero_copy_only=False), dtype=bool)
    t_int = np.where(t_valid, np.asarray(times.cast(pa.int64()).fill_null(0).to_numpy(), np.int64), 0)
    no_name = codes < 0
    future = t_valid & (t_int > _latest_time_ns())
    is_placeholder = np.isin(values, np.asarray(placeholders, dtype=np.float64)) | (np.isnan(values) & ~value_null)
    with np.errstate(invalid="ignore"):
        is_absurd = ~np.isnan(values) & ~(np.abs(values) <= MAX_ABS_VALUE)  # inf, -inf, 1e300
    # Order of judgement: missing time or name -> empty value -> placeholder -> absurd -> not in decoder.
    drop_missing = ~t_valid | no_name | future
    drop_empty = ~drop_missing & value_null
    drop_placeholder = ~drop_missing & ~drop_empty & is_placeholder
    drop_absurd = ~drop_missing & ~drop_empty & ~drop_placeholder & is_absurd
    drop_unknown = ~drop_missing & ~drop_empty & ~drop_placeholder & ~drop_absurd & ~row_known
    keep = ~(drop_missing | drop_empty | drop_placeholder | drop_absurd | drop_unknown)
    counts["rows read"] = n0
    counts["blank rows"] += n_blank
    if bad_values:
        counts["unparseable values"] += bad_values
    unknown_names: Counter[str] = Counter()
    counted = ~drop_missing & ~drop_empty & ~drop_placeholder & ~drop_absurd
    rows_per_code = np.bincount(codes_safe[counted], minlength=len(pseudo_of_code) + 1)
    for c in unknown_codes:
        if rows_per_code[c]:
            unknown_names[name_token(str(dictionary[c]))] += int(rows_per_code[c])

    pseudo_arr = np.array([p if p is not None else "" for p in pseudo_of_code] + [""], dtype=object)
    day_idx = np.where(t_valid, t_int // DAY_NS, -1)
    sc_pseudo = np.array([decoder.spacecraft_of(p) if p else "" for p in pseudo_arr], dtype=object)
    reports = _DayReports(pseudonymise_text(path.name, decoder))
    # Per-day counts of artifacts that have a day and a spacecraft.
    for label, mask in (
        ("empty values", drop_empty),
        ("placeholder values", drop_placeholder),
        (ARCHIVE_ABSURD, drop_absurd),
        ("names not in the decoder", drop_unknown),
    ):
        sel = mask & t_valid
        if not sel.any():
            continue
        for (sc, d), n in Counter(zip(sc_pseudo[codes_safe[sel]], day_idx[sel], strict=True)).items():
            reports(sc or "unattributed", d).removed[label] += n
    missing_time_rows = int(np.count_nonzero(~t_valid))
    if missing_time_rows:
        counts["rows without a time"] += missing_time_rows
    if future.any():
        counts[ARCHIVE_FUTURE] += int(np.count_nonzero(future))
    no_name_rows = int(np.count_nonzero(no_name & t_valid))
    if no_name_rows:
        counts["rows without a mnemonic"] += no_name_rows
    counts.update(_unknown_name_counts(unknown_names, sum(1 for c in unknown_codes if rows_per_code[c])))

    # Categories sorted by name: sorting by mnemonic code groups each spacecraft's mnemonics
    # (names sharing the prefix "SC-A." are contiguous) and orders them by name.
    pseudo_names = sorted({p for p in pseudo_of_code if p is not None})
    sc_names = sorted({decoder.spacecraft_of(p) for p in pseudo_names})
    p_index = {p: i for i, p in enumerate(pseudo_names)}
    code_to_pseudo = np.array([p_index[p] if p is not None else -1 for p in pseudo_of_code] + [-1], dtype=np.int64)
    pseudo_to_sc = np.array([sc_names.index(decoder.spacecraft_of(p)) for p in pseudo_names], dtype=np.int64)
    ch = _Channels(pseudo_names, sc_names, pseudo_to_sc, reports)
    idx = np.flatnonzero(keep)
    m_codes, t_k, v_k = code_to_pseudo[codes_safe[idx]], t_int[idx], values[idx]
    del values, t_int, codes, codes_safe, idx
    m_codes, t_k, v_k = _sort_and_dedupe(m_codes, t_k, v_k, ch)
    _count_kept(m_codes, t_k, ch)
    return ArchiveChunk(samples=_samples_frame(m_codes, t_k, v_k, ch), per_day=reports.per_day, file_counts=counts)
