"""Chunks with carry-over: long series cut into pieces whose results do not depend on the cut.

DESIGN.md ("Scale"): work is split into (spacecraft, time chunk) tasks whose chunks overlap by the
detector's window. A :class:`Chunk` *owns* rows ``[own_start, own_stop)`` and *reads* rows
``[start, stop)``: ``carry_before`` rows of the previous chunk (a sliding statistic's pre-window, a
filter's warm-up) and ``carry_after`` rows of the next (a post-window). A detector runs on the rows
it reads and keeps only the results at rows it owns (:meth:`Chunk.owns`); the owned ranges tile the
series exactly once, so the union of the chunks' results is the result on the whole series.

>>> [(c.start, c.own_start, c.own_stop, c.stop) for c in chunk_rows(10, 4, carry_before=2, carry_after=1)]
[(0, 0, 4, 5), (2, 4, 8, 9), (6, 8, 10, 10)]
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from abrupt.series.telemetry import Telemetry


@dataclass(frozen=True)
class Chunk:
    """Row ranges of one chunk: read ``[start, stop)``, own ``[own_start, own_stop)`` (absolute rows)."""

    index: int
    start: int
    own_start: int
    own_stop: int
    stop: int

    @property
    def carry_before(self) -> int:
        return self.own_start - self.start

    def owns(self, rows: ArrayLike, *, relative: bool = True) -> NDArray[np.bool_]:
        """Which of ``rows`` this chunk owns; rows are chunk-relative (0 = ``start``) unless ``relative=False``."""
        r = np.asarray(rows, dtype=np.int64) + (self.start if relative else 0)
        return np.asarray((r >= self.own_start) & (r < self.own_stop))


def chunk_rows(n_rows: int, chunk_rows: int, *, carry_before: int = 0, carry_after: int = 0) -> list[Chunk]:
    """Cut ``n_rows`` into chunks owning ``chunk_rows`` rows each, reading the carry-over around them."""
    if chunk_rows < 1 or carry_before < 0 or carry_after < 0:
        raise ValueError(
            f"need chunk_rows >= 1 and non-negative carry-over; got {chunk_rows}, {carry_before}, {carry_after}"
        )
    out = []
    for i, own_start in enumerate(range(0, max(n_rows, 0), chunk_rows)):
        own_stop = min(n_rows, own_start + chunk_rows)
        out.append(Chunk(i, max(0, own_start - carry_before), own_start, own_stop, min(n_rows, own_stop + carry_after)))
    return out


def telemetry_chunks(
    telemetry: Telemetry, chunk_s: float, *, carry_before_s: float = 0.0, carry_after_s: float = 0.0
) -> Iterator[tuple[Chunk, Telemetry]]:
    """Chunks of ``chunk_s`` seconds of telemetry with carry-over (converted to rows at the nominal rate)."""
    rate = telemetry.sample_rate_hz
    per = max(1, round(chunk_s * rate))
    before = int(np.ceil(carry_before_s * rate - 1e-9))  # 1e-9: 0.1 s steps are not exact in binary
    after = int(np.ceil(carry_after_s * rate - 1e-9))
    for chunk in chunk_rows(len(telemetry), per, carry_before=before, carry_after=after):
        yield chunk, telemetry.rows(chunk.start, chunk.stop)
