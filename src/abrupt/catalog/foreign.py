"""Tables of the catalog's names that abrupt did not create: found before anything is written.

A catalog made by abrupt holds an ``abrupt_schema`` table. abrupt 0.1 wrote none; its ``events`` and
``runs`` tables had at least the columns of :data:`V1_COLUMNS`. Any other table named like one of
abrupt's is another program's, and the catalog refuses the database rather than migrate, drop or
fill that table.
"""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd
import sqlalchemy as sa

V1_COLUMNS = {
    "events": {"spacecraft", "detector", "kind", "time_utc"},
    "runs": {"run_id", "command"},
}


def foreign_table(conn: sa.Connection, later_tables: Sequence[sa.Table], marker: str) -> str | None:
    """The reason a database holds a table abrupt did not create, or None.

    ``later_tables`` are abrupt's tables added after 0.1 (they must have all their columns).
    """
    inspector = sa.inspect(conn)
    names = set(inspector.get_table_names())
    if marker in names:
        return None
    needed = dict(V1_COLUMNS) | {t.name: {c.name for c in t.c} for t in later_tables}
    for table, columns in needed.items():
        if table in names:
            missing = columns - {c["name"] for c in inspector.get_columns(table)}
            if missing:
                first = sorted(missing)[0]
                return f"holds a table {table!r} that abrupt did not create (no column {first!r}, no {marker} table)"
    return None


def too_long_text(frame: pd.DataFrame, table: sa.Table) -> str | None:
    """The first text of ``frame`` longer than its column of ``table`` allows, or None.

    SQLite stores a longer text without a word, PostgreSQL refuses it mid-run: the same limit is
    checked on both, before anything is written.
    """
    for column in table.c:
        limit = getattr(column.type, "length", None)
        if limit is None or column.name not in frame or not len(frame):
            continue
        lengths = frame[column.name].astype("string").str.len().fillna(0)
        if (lengths > limit).any():
            value = str(frame[column.name].astype("string")[lengths > limit].iloc[0])
            return f"{column.name} {value[:40]!r}… has {len(value)} characters; the catalog holds at most {limit}"
    return None
