"""Export of a telemetry store: the stored samples of one spacecraft as a long archive.

The store (:mod:`abrupt.store`, written by ``abrupt ingest``) holds pseudonymised raw samples, one
Parquet file per spacecraft-day. :func:`export_store` writes them out again in the long archive layout
``abrupt ingest`` reads (``time,mnemonic,value``; :mod:`abrupt.readers.archive`), so an archive can be
handed on, inspected with any tool, or ingested into another store with a decoder that maps each
pseudonym to itself, which gives back the same samples. Names stay pseudonyms: the decoder is never
read here. Days are streamed one at a time, so memory holds one day whatever the store's size.

CSV times are ISO-8601 UTC with a ``Z`` and nanoseconds; Parquet times are UTC timestamps (ns).
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from abrupt.errors import InputError
from abrupt.pipelines.flight import day_range
from abrupt.store import TelemetryStore

EXPORT_SCHEMA = pa.schema([("time", pa.timestamp("ns", tz="UTC")), ("mnemonic", pa.string()), ("value", pa.float64())])


@dataclass(frozen=True)
class StoreExport:
    """What :func:`export_store` wrote: the file, the days and the samples."""

    out: Path
    days: tuple[str, ...]
    samples: int


def _day_table(store: TelemetryStore, spacecraft: str, day: str) -> pa.Table:
    frame = store.read_day(spacecraft, day)
    frame = frame.sort_values(["time", "mnemonic"], kind="stable")
    return pa.table(
        {
            "time": pa.array(frame["time"].to_numpy(dtype="datetime64[ns]"), pa.timestamp("ns")).cast(
                pa.timestamp("ns", tz="UTC")
            ),
            "mnemonic": pa.array(frame["mnemonic"].astype(str).to_numpy(), pa.string()),
            "value": pa.array(frame["value"].to_numpy(dtype=float), pa.float64()),
        },
        schema=EXPORT_SCHEMA,
    )


def _csv_frame(table: pa.Table) -> pd.DataFrame:
    """The day as CSV columns: ISO-8601 UTC times with nanoseconds and a ``Z`` (vectorised)."""
    times = np.datetime_as_string(table.column("time").cast(pa.timestamp("ns")).to_numpy(), unit="ns")
    return pd.DataFrame(
        {
            "time": np.char.add(times.astype(str), "Z"),
            "mnemonic": table.column("mnemonic").to_numpy(zero_copy_only=False),
            "value": table.column("value").to_numpy(),
        }
    )


def export_store(
    store_root: str | Path, spacecraft: str, out: str | Path, *, days: Iterable[str] | None = None
) -> StoreExport:
    """Write the stored samples of ``spacecraft`` (every day, or ``days``: ``YYYY-MM-DD`` or ``A..B``) to
    ``out`` (``.csv`` or ``.parquet``) in the long archive layout, through a temporary file renamed into
    place. An unknown spacecraft or day is an :class:`~abrupt.errors.InputError` naming what the store holds."""
    store = TelemetryStore(store_root)
    out = Path(out)
    if not out.name.lower().endswith((".csv", ".parquet")):
        raise InputError("an exported archive must end in .csv or .parquet", file=out)
    if not store.root.is_dir():
        raise InputError("no such store folder", file=store.root)
    if not store.days(spacecraft):
        held = ", ".join(f"{sc} ({len(store.days(sc))} days)" for sc in store.spacecraft()) or "nothing"
        raise InputError(f"no stored days for spacecraft {spacecraft!r}; the store holds {held}", file=store.root)
    chosen = day_range(store, spacecraft, days)
    tmp = out.with_name(f".{out.name}.{uuid.uuid4().hex[:12]}.tmp")
    n = 0
    try:
        if out.suffix.lower() == ".csv":
            with tmp.open("w", encoding="utf-8") as fh:
                for k, day in enumerate(chosen):
                    table = _day_table(store, spacecraft, day)
                    _csv_frame(table).to_csv(fh, index=False, header=k == 0)
                    n += table.num_rows
        else:
            with pq.ParquetWriter(tmp, EXPORT_SCHEMA) as writer:
                for day in chosen:
                    table = _day_table(store, spacecraft, day)
                    writer.write_table(table)
                    n += table.num_rows
        os.replace(tmp, out)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return StoreExport(out, tuple(chosen), n)
