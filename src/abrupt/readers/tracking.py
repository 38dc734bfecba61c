"""One entry point for ground-tracking measurement files, recognised from their content.

:func:`read_tracking` reads ILRS CRD (``H1 CRD`` …; full rate or normal points, plain or compressed),
CCSDS TDM in KVN (``CCSDS_TDM_VERS``) and the ``.aer`` text format of Orekit's tutorials, into the
standard measurement table of :mod:`abrupt.model.tracking_measurements` (CRD adds its own columns:
meteorology, time of flight, epoch event; see :mod:`abrupt.readers.crd`).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Literal

import pandas as pd

from abrupt.errors import RepairLog
from abrupt.readers.aer import read_aer
from abrupt.readers.compression import read_bytes
from abrupt.readers.crd import read_crd
from abrupt.readers.tdm import read_tdm

TrackingFormat = Literal["crd", "tdm", "aer"]


def sniff_tracking_format(path: str | Path) -> TrackingFormat:
    """``crd``, ``tdm`` or ``aer`` from the first meaningful line of the (decompressed) file."""
    text = read_bytes(path)[:8192].decode("latin-1")
    for line in text.splitlines():
        tokens = line.split()
        if not tokens or tokens[0] in ("00", "COMMENT") or tokens[0].startswith("#"):
            continue
        if tokens[0].upper() == "H1" and len(tokens) > 1 and tokens[1].upper() == "CRD":
            return "crd"
        if tokens[0].upper().startswith("CCSDS_TDM_VERS"):
            return "tdm"
        return "aer"
    return "aer"


def read_tracking(
    path: str | Path, *, known_stations: Iterable[str] | None = None, repairs: RepairLog | None = None
) -> pd.DataFrame:
    """Read a CRD, TDM or ``.aer`` file; stations outside ``known_stations`` are an error (CRD, .aer)."""
    fmt = sniff_tracking_format(path)
    if fmt == "crd":
        return read_crd(path, known_stations=known_stations, repairs=repairs)
    if fmt == "tdm":
        return read_tdm(path, repairs=repairs)

    return read_aer(path, known_stations=known_stations, repairs=repairs)
