"""Parquet store of pseudonymised raw telemetry samples, partitioned by spacecraft and UTC day.

Layout (Harris et al. 2025 §3.3: one file per spacecraft-day, pseudonymised names only)::

    STORE/spacecraft=SC-A/day=2026-03-10/samples.parquet   columns mnemonic, time (UTC ns), value
    STORE/spacecraft=SC-A/day=2026-03-10/ingest.json       the day's ingest report

Samples are raw (as telemetered, artifacts removed); synchronisation onto a grid happens later
(:mod:`abrupt.series.timetable`), so the store never depends on a processing choice. A day keeps one
version of each sample: re-ingesting the same archive changes nothing (rows and counters alike), and a
corrected archive replaces the stored samples within its time span, said in the day's report and
counted (``versions_replaced``).
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from abrupt.errors import InputError
from abrupt.outputs import atomic_output, write_text_atomic

SAFE_NAME = re.compile(r"^[A-Za-z0-9_.+-]+$")


class TelemetryStore:
    """A directory of raw samples: one Parquet file and one ingest report per spacecraft-day."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)

    def _dir(self, spacecraft: str, day: str) -> Path:
        if not SAFE_NAME.match(spacecraft):
            raise InputError(f"spacecraft pseudonym {spacecraft!r} is not a safe directory name", file=self.root)
        return self.root / f"spacecraft={spacecraft}" / f"day={day}"

    def spacecraft(self) -> list[str]:
        """Pseudonyms of the spacecraft in the store."""
        return sorted(p.name.split("=", 1)[1] for p in self.root.glob("spacecraft=*") if p.is_dir())

    def days(self, spacecraft: str) -> list[str]:
        """ISO days (``YYYY-MM-DD``) stored for a spacecraft, in order."""
        base = self.root / f"spacecraft={spacecraft}"
        return sorted(p.name.split("=", 1)[1] for p in base.glob("day=*") if (p / "samples.parquet").exists())

    def holdings(self) -> str:
        """What the store holds, for an error naming a spacecraft it does not: each pseudonym with its
        number of days and their span (a spacecraft file's ``name`` is the pseudonym its days are under)."""
        held = [(name, days) for name in self.spacecraft() if (days := self.days(name))]
        if not held:
            return "the store holds no spacecraft days (ingest archives into it first: abrupt ingest)"
        listing = ", ".join(f"{name!r} ({len(days)} day(s), {days[0]}..{days[-1]})" for name, days in held)
        return f"the store holds {listing}: give the spacecraft file whose name is one of these"

    def write_day(self, spacecraft: str, day: str, samples: pd.DataFrame, report: dict[str, Any]) -> int:
        """Store one archive's ``samples`` (mnemonic, time, value) of a day; return the rows added.

        The day keeps one version of each sample (:func:`merge_version`): an archive that agrees with
        what is stored adds only what is new (a repeated ingest adds nothing and changes no counter); an
        archive that disagrees (another value at a stored mnemonic and time, or the same archive name with
        other content: a corrected archive) replaces the stored samples within its own time span, and the
        day's report says so and counts it. The report keeps each archive's counts once
        (``archives``), so the day's totals are sums over the archives it holds, never over ingests.
        Both files are written atomically (the samples first, then the report)."""
        d = self._dir(spacecraft, day)
        path = d / "samples.parquet"
        new = _normalised(samples)
        source = ",".join(str(x) for x in report.get("sources", [])) or "<unnamed>"
        digest = _digest(new)
        prev = self.report(spacecraft, day) if path.exists() else {}
        archives: dict[str, dict[str, Any]] = dict(prev.get("archives") or {})
        if not archives and prev:  # a report written before archives were kept apart: one entry
            archives[",".join(prev.get("sources", [])) or "<earlier ingest>"] = _counts(prev)
        if path.exists() and archives.get(source, {}).get("digest") == digest:
            _read_table(path, columns=["mnemonic"])  # "unchanged" only if the stored samples still read
            self._write_report(d, {**prev, "last_ingest": f"{source}: unchanged (already stored)"})
            return 0
        old = _normalised(self.read_day(spacecraft, day)) if path.exists() else new.iloc[:0]
        span = (int(new["time"].min()), int(new["time"].max())) if len(new) else (0, -1)
        # the earlier versions: stored archives whose time span meets this one's (or the same name)
        earlier = {
            name: tuple(entry.get("span_ns") or (-(2**62), 2**62))
            for name, entry in archives.items()
            if name == source or _meets(tuple(entry.get("span_ns") or (-(2**62), 2**62)), span)
        }
        reach = (
            min([span[0], *(lo for lo, _ in earlier.values())]),
            max([span[1], *(hi for _, hi in earlier.values())]),
        )
        merged = merge_version(old, new, replace=source in archives, span_ns=reach)
        if merged.replaced or source in archives:
            for name in earlier:
                archives.pop(name, None)  # replaced by this version: its counts go with it
        archives[source] = {**_counts(report), "digest": digest, "span_ns": list(span)}
        d.mkdir(parents=True, exist_ok=True)
        with atomic_output(path) as tmp:
            pq.write_table(_sorted_table(merged.frame), tmp, compression="zstd")
        out = {
            **{k: v for k, v in report.items() if k not in _COUNT_KEYS},
            **_totals(archives),
            "archives": archives,
            "sources": sorted(archives),
            "rows_stored": len(merged.frame),
            "versions_replaced": int(prev.get("versions_replaced", 0)) + (1 if merged.replaced else 0),
            "last_ingest": merged.describe(source),
        }
        self._write_report(d, out)
        return merged.added

    @staticmethod
    def _write_report(d: Path, report: dict[str, Any]) -> None:
        write_text_atomic(d / "ingest.json", json.dumps(report, indent=1, sort_keys=True))

    def read_day(self, spacecraft: str, day: str, mnemonics: Iterable[str] | None = None) -> pd.DataFrame:
        """Samples of one day (mnemonic, time, value); empty frame if the day is not stored."""
        path = self._dir(spacecraft, day) / "samples.parquet"
        if not path.exists():
            return pd.DataFrame(
                {"mnemonic": pd.Series([], dtype=str), "time": pd.Series([], dtype="datetime64[ns]"), "value": []}
            )
        filt = None
        if mnemonics is not None:
            filt = [("mnemonic", "in", list(mnemonics))]
        table = _read_table(path, filters=filt)
        # Naive datetime64[ns] holding UTC: tz-aware columns turn into Python objects on to_numpy.
        time_idx = table.schema.get_field_index("time")
        table = table.set_column(time_idx, "time", table.column("time").cast(pa.timestamp("ns")))
        return table.to_pandas()

    def read_range(
        self, spacecraft: str, start: np.datetime64, end: np.datetime64, mnemonics: Iterable[str] | None = None
    ) -> pd.DataFrame:
        """Samples with start <= time < end from every day partition the interval touches.

        Columns ``mnemonic`` (categorical), ``time`` (naive datetime64[ns] holding UTC) and ``value``;
        rows sorted by mnemonic, then time (each day is stored that way). Read column-wise through
        pyarrow straight into numpy (no per-row Python work).
        """
        mn = list(mnemonics) if mnemonics is not None else None
        d0 = start.astype("datetime64[D]")
        d1 = (end - np.timedelta64(1, "ns")).astype("datetime64[D]")
        t_lo = int(start.astype("datetime64[ns]").astype(np.int64))
        t_hi = int(end.astype("datetime64[ns]").astype(np.int64))
        names: list[str] = []
        index: dict[str, int] = {}
        codes_l, t_l, v_l = [], [], []
        for d in np.arange(d0, d1 + np.timedelta64(1, "D"), dtype="datetime64[D]"):
            path = self._dir(spacecraft, str(d)) / "samples.parquet"
            if not path.exists():
                continue
            table = _read_table(path, columns=["mnemonic", "time", "value"])
            mcol = table.column("mnemonic").combine_chunks()
            if not pa.types.is_dictionary(mcol.type):
                mcol = mcol.dictionary_encode()
            day_names = mcol.dictionary.to_pylist()
            remap = np.array([index.setdefault(str(x), len(index)) for x in day_names] + [-1], dtype=np.int32)
            for x in day_names:
                if str(x) not in names:
                    names.append(str(x))
            codes = remap[np.asarray(mcol.indices.fill_null(len(day_names)).to_numpy(zero_copy_only=False))]
            t = np.asarray(table.column("time").cast(pa.int64()).to_numpy(), dtype=np.int64)
            v = np.asarray(table.column("value").to_numpy(), dtype=np.float64)
            keep = (t >= t_lo) & (t < t_hi)
            if mn is not None:
                wanted = np.zeros(len(index) + 1, bool)
                for x in mn:
                    if x in index:
                        wanted[index[x]] = True
                keep &= wanted[codes]
            codes_l.append(codes[keep])
            t_l.append(t[keep])
            v_l.append(v[keep])
        if not codes_l:
            return self.read_day(spacecraft, "0000-00-00", mn)
        codes = np.concatenate(codes_l)
        t = np.concatenate(t_l)
        v = np.concatenate(v_l)
        # Sorted by mnemonic, then time: each day is stored so and days come in time order, so a
        # stable sort on the codes (radix sort on 16-bit codes) keeps the time order.
        small = codes.astype(np.int16) if len(index) < 32_000 else codes
        order = np.argsort(small, kind="stable")
        cats = pd.Categorical.from_codes(codes[order], categories=pd.Index(names, dtype=object), validate=False)
        return pd.DataFrame({"mnemonic": cats, "time": t[order].view("datetime64[ns]"), "value": v[order]})

    def report(self, spacecraft: str, day: str) -> dict[str, Any]:
        """The ingest report of a day ({} when absent); a report that is not a JSON object is an
        :class:`~abrupt.errors.InputError` naming the file."""
        path = self._dir(spacecraft, day) / "ingest.json"
        if not path.exists():
            return {}
        try:
            report = json.loads(path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise InputError(
                f"ingest report is not valid JSON ({exc}); restore it, or remove the day's folder and ingest again",
                file=path,
            ) from None
        if not isinstance(report, dict):
            raise InputError("ingest report is not a JSON object; restore it, or remove the day's folder", file=path)
        return report


def _read_table(path: Path, **options: Any) -> pa.Table:
    """A stored day's samples; a file that does not read (cut by a kill or a full disk, or not written by
    abrupt) is an :class:`InputError` naming it, never silently an empty or partial day."""
    try:
        return pq.read_table(path, **options)
    except (pa.ArrowInvalid, OSError) as exc:
        why = str(exc).split(": ", 1)[-1].split(".")[0][:80]
        raise InputError(
            f"stored samples do not read ({why}); the file was cut or damaged: move the day's folder aside and "
            "ingest its archives again",
            file=path,
        ) from None


def _sorted_table(frame: pd.DataFrame) -> pa.Table:
    """The stored table: dictionary-encoded mnemonic, UTC time, value; sorted by mnemonic name, then time."""
    mn = frame["mnemonic"].astype("category")
    names = np.asarray(mn.cat.categories.astype(str), dtype=object)
    rank = np.empty(names.size, np.int32)
    rank[np.argsort(names, kind="stable")] = np.arange(names.size, dtype=np.int32)
    key = rank[mn.cat.codes.to_numpy()] if names.size else np.empty(0, np.int32)
    t = pd.DatetimeIndex(frame["time"])
    if t.tz is not None:
        t = t.tz_convert("UTC").tz_localize(None)
    t_ns = t.asi8
    v = frame["value"].to_numpy(np.float64)
    ordered = key.size < 2 or bool(np.all((key[1:] > key[:-1]) | ((key[1:] == key[:-1]) & (t_ns[1:] >= t_ns[:-1]))))
    if not ordered:
        o = np.lexsort((t_ns, key))
        key, t_ns, v = key[o], t_ns[o], v[o]
    sorted_names = pa.array(np.sort(names).tolist() if names.size else [], pa.string())
    return pa.table(
        {
            "mnemonic": pa.DictionaryArray.from_arrays(pa.array(key, pa.int32()), sorted_names),
            "time": pa.array(t_ns, pa.int64()).cast(pa.timestamp("ns", tz="UTC")),
            "value": pa.array(v, pa.float64()),
        }
    )


_COUNT_KEYS = ("rows_kept", "removed", "reported", "samples_per_channel")


def _counts(report: dict[str, Any]) -> dict[str, Any]:
    """The counters of one archive's report for a day."""
    return {
        "rows_kept": int(report.get("rows_kept", 0)),
        **{key: dict(report.get(key) or {}) for key in ("removed", "reported", "samples_per_channel")},
    }


def _totals(archives: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The day's counters: sums over the archives it holds (each counted once, however often ingested)."""
    out: dict[str, Any] = {"rows_kept": sum(int(a.get("rows_kept", 0)) for a in archives.values())}
    for key in ("removed", "reported", "samples_per_channel"):
        merged: dict[str, int] = {}
        for entry in archives.values():
            for k, v in (entry.get(key) or {}).items():
                merged[k] = merged.get(k, 0) + int(v)
        out[key] = dict(sorted(merged.items()))
    return out


def _normalised(samples: pd.DataFrame) -> pd.DataFrame:
    """mnemonic (categorical of str, sorted names), time (int64 ns UTC), value (float64)."""
    t = pd.DatetimeIndex(samples["time"])
    if t.tz is not None:
        t = t.tz_convert("UTC").tz_localize(None)
    mnemonic = samples["mnemonic"].astype("category")
    names = pd.Index(mnemonic.cat.categories.astype(str))
    order = np.argsort(names.to_numpy(dtype=object), kind="stable")
    rank = np.empty(order.size, np.int64)
    rank[order] = np.arange(order.size)
    codes = mnemonic.cat.codes.to_numpy()
    sorted_codes = np.where(codes >= 0, rank[np.maximum(codes, 0)] if rank.size else 0, -1)
    return pd.DataFrame(
        {
            "mnemonic": pd.Categorical.from_codes(sorted_codes, names[order]),
            "time": t.asi8,
            "value": samples["value"].to_numpy(np.float64),
        }
    )


def _digest(frame: pd.DataFrame) -> str:
    """SHA-256 of samples' content in a canonical order (independent of row order and file name)."""
    codes = frame["mnemonic"].cat.codes.to_numpy(np.int64)  # over sorted names (:func:`_normalised`)
    t = frame["time"].to_numpy(np.int64)
    v = frame["value"].to_numpy(np.float64)
    order = np.lexsort((v, t, codes))
    h = hashlib.sha256()
    h.update("\n".join(map(str, frame["mnemonic"].cat.categories)).encode())
    for column in (codes, t, v):
        h.update(np.ascontiguousarray(column[order]).tobytes())
    return h.hexdigest()


@dataclass(frozen=True)
class MergedDay:
    """A day's samples after one archive was stored: the frame, rows added, stored rows replaced."""

    frame: pd.DataFrame
    added: int
    replaced: int
    conflicts: int

    def describe(self, source: str) -> str:
        if self.replaced:
            why = f"{self.conflicts} sample(s) with another value" if self.conflicts else "a new version of it"
            return (
                f"{source}: replaced the stored version of the day within its time span ({why}): "
                f"{self.replaced} stored row(s) removed, {self.added} row(s) added"
            )
        return f"{source}: {self.added} row(s) added"


def _common_names(a: pd.DataFrame, b: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Both frames with their mnemonic categoricals over the same (sorted) names, so that they concatenate
    as one categorical."""
    a, b = (f.assign(mnemonic=f["mnemonic"].astype("category")) for f in (a, b))
    names = a["mnemonic"].cat.categories.union(b["mnemonic"].cat.categories)
    out = []
    for frame in (a, b):
        remap = names.get_indexer(frame["mnemonic"].cat.categories)
        codes = frame["mnemonic"].cat.codes.to_numpy()
        new_codes = np.where(codes >= 0, remap[np.maximum(codes, 0)] if remap.size else 0, -1)
        out.append(frame.assign(mnemonic=pd.Categorical.from_codes(new_codes, names)))
    return out[0], out[1]


def _sample_keys(a: pd.DataFrame, b: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """One int64 key per (mnemonic, time) row of two frames of :func:`_common_names`: the mnemonic's code
    in the high bits, nanoseconds since the earlier start in the low 47 (a day is 8.6e13 ns < 2^47)."""
    names = a["mnemonic"].cat.categories
    times = np.concatenate([a["time"].to_numpy(np.int64), b["time"].to_numpy(np.int64)])
    t0 = int(times.min()) if times.size else 0
    if times.size and (int(times.max()) - t0 >= 1 << 47 or len(names) >= 1 << 15):
        raise InputError("a stored day spans more than 1.6 days or holds 32768 channels or more")
    out = []
    for frame in (a, b):
        code = frame["mnemonic"].cat.codes.to_numpy(np.int64)
        out.append((code << 47) | (frame["time"].to_numpy(np.int64) - t0))
    return out[0], out[1]


def _lookup(keys: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Index in ``keys`` of each of ``wanted`` (its first occurrence), -1 where absent."""
    first = ~pd.Index(keys).duplicated()
    positions = np.flatnonzero(first)
    found = pd.Index(keys[first]).get_indexer(wanted)
    return np.where(found >= 0, positions[np.maximum(found, 0)], -1) if positions.size else found


def _gather(values: np.ndarray, index: np.ndarray) -> np.ndarray:
    """``values[index]`` with NaN where ``index`` is -1."""
    if not values.size:
        return np.full(index.size, np.nan)
    return np.where(index >= 0, values[np.maximum(index, 0)], np.nan)


def _equal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return (a == b) | (np.isnan(a) & np.isnan(b))


def _meets(a: tuple[int, ...], b: tuple[int, ...]) -> bool:
    return a[0] <= b[1] and b[0] <= a[1]


def merge_version(
    old: pd.DataFrame, new: pd.DataFrame, *, replace: bool = False, span_ns: tuple[int, int] | None = None
) -> MergedDay:
    """One version of a day from the stored samples ``old`` and an archive's ``new`` (normalised frames).

    Samples equal in mnemonic, time and value are kept once. When ``new`` holds another value at a stored
    mnemonic and time (a corrected archive), or ``replace`` (the same archive name was stored with other
    content), every stored sample within ``span_ns`` (default: ``new``'s time span; the store widens it
    to the spans of the earlier versions) is replaced by ``new``; stored samples outside it (another
    archive's part of the day) are kept. ``added`` and ``replaced`` count the rows that differ: rows
    stored again unchanged count in neither."""
    old, new = _common_names(old, new)
    key_old, key_new = _sample_keys(old, new)
    at_new = _lookup(key_new, key_old)  # row of new at each old row's mnemonic and time (-1: none)
    at_old = _lookup(key_old, key_new)
    same_old = (at_new >= 0) & _equal(old["value"].to_numpy(), _gather(new["value"].to_numpy(), at_new))
    same_new = (at_old >= 0) & _equal(new["value"].to_numpy(), _gather(old["value"].to_numpy(), at_old))
    conflicts = int(((at_new >= 0) & ~same_old).sum())
    if (conflicts or replace) and len(new):
        lo, hi = span_ns if span_ns is not None else (int(new["time"].min()), int(new["time"].max()))
        inside = ((old["time"] >= lo) & (old["time"] <= hi)).to_numpy()
        frame = pd.concat([old.loc[~inside], new], ignore_index=True)
        return MergedDay(frame, int((~same_new).sum()), int((inside & ~same_old).sum()), conflicts)
    fresh = new.loc[at_old < 0]
    return MergedDay(pd.concat([old, fresh], ignore_index=True), len(fresh), 0, 0)
