"""Parquet store of pseudonymised raw telemetry samples, partitioned by spacecraft and UTC day.

Layout (Harris et al. 2025 §3.3: one file per spacecraft-day, pseudonymised names only)::

    STORE/spacecraft=SC-A/day=2026-03-10/samples.parquet   columns mnemonic, time (UTC ns), value
    STORE/spacecraft=SC-A/day=2026-03-10/ingest.json       the day's ingest report

Samples are raw (as telemetered, artifacts removed); synchronisation onto a grid happens later
(:mod:`abrupt.series.timetable`), so the store never depends on a processing choice. Re-ingesting
the same archive merges into the partition without duplicating rows.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from abrupt.errors import InputError

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
        """Merge ``samples`` (mnemonic, time, value) into the partition; return rows added."""
        d = self._dir(spacecraft, day)
        d.mkdir(parents=True, exist_ok=True)
        path = d / "samples.parquet"
        new = samples[["mnemonic", "time", "value"]]
        added = len(new)
        if path.exists():
            new = new.copy()
            new["mnemonic"] = new["mnemonic"].astype(str)
            old = self.read_day(spacecraft, day)
            old["mnemonic"] = old["mnemonic"].astype(str)
            old["time"] = old["time"].dt.tz_localize("UTC")
            both = pd.concat([old, new], ignore_index=True)
            both = both.drop_duplicates(["mnemonic", "time", "value"], keep="first")
            added = len(both) - len(old)
            new = both
            prev = self.report(spacecraft, day)
            report = _merge_reports(prev, report) if prev else report
        table = _sorted_table(new)
        tmp = path.with_suffix(".tmp")
        pq.write_table(table, tmp, compression="zstd")
        tmp.replace(path)
        report = {**report, "rows_stored": len(new)}
        (d / "ingest.json").write_text(json.dumps(report, indent=1, sort_keys=True))
        return added

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
        table = pq.read_table(path, filters=filt)
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
            table = pq.read_table(path, columns=["mnemonic", "time", "value"])
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
        """The ingest report of a day ({} when absent)."""
        path = self._dir(spacecraft, day) / "ingest.json"
        return dict(json.loads(path.read_text())) if path.exists() else {}


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


def _merge_reports(a: dict[str, Any], b: dict[str, Any]) -> dict[str, Any]:
    out = dict(a)
    for key in ("removed", "reported", "samples_per_channel"):
        merged = dict(a.get(key, {}))
        for k, v in b.get(key, {}).items():
            merged[k] = merged.get(k, 0) + v
        out[key] = merged
    out["rows_kept"] = a.get("rows_kept", 0) + b.get("rows_kept", 0)
    out["sources"] = sorted(set(a.get("sources", [])) | set(b.get("sources", [])))
    return out
