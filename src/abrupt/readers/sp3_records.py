"""Whether the last epoch of an SP3 body is whole (used when a header count does not match the body)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence


def last_epoch_complete(body: Sequence[str], satellites: Sequence[str], has_velocity: bool) -> bool:
    """Whether the records of the last epoch are whole in a file without ``EOF``: as many position
    (and velocity) records as the epoch before it holds (the header's satellite count when there is
    one epoch), and a last line as long as the record of its kind before it. ``body``: the lines from
    the first epoch record on."""
    blocks: list[Counter[str]] = []
    lengths: dict[str, list[int]] = {"P": [0, 0], "V": [0, 0]}  # per record type: previous, last
    last_tag = "P"
    for line in body:
        if line.startswith("*"):
            blocks.append(Counter())
        elif line[:1] in ("P", "V") and blocks:
            last_tag = line[0]
            blocks[-1][last_tag] += 1
            lengths[last_tag] = [lengths[last_tag][1], len(line.rstrip())]
    if not blocks:
        return False
    wanted = blocks[-2] if len(blocks) > 1 else Counter({"P": len(satellites)})
    if has_velocity and len(blocks) == 1:
        wanted["V"] = len(satellites)
    full = all(blocks[-1][k] >= n for k, n in wanted.items())
    previous, last = lengths[last_tag]
    return full and last >= previous
