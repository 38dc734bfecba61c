"""One entry point for orbit files: the format is recognised from the content, not the file name.

:func:`read_ephemeris` reads SP3-a/b/c/d, CCSDS OEM (KVN or XML), CCSDS OPM (KVN), ILRS CPF and
navigation CSV, plain or compressed (gzip ``.gz``, Unix ``.Z``). :func:`write_ephemeris` writes an
ephemeris in the format of a given input file (SP3, OEM KVN, OEM XML; navigation CSV for the others or
when the output name ends in ``.csv``), so that ``abrupt inject orbit`` returns the input's own format.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import numpy as np

from abrupt.errors import InputError
from abrupt.readers.compression import read_bytes
from abrupt.readers.cpf import read_cpf
from abrupt.readers.navigation_csv import read_navigation_csv, write_navigation_csv
from abrupt.readers.oem import TIME_SYSTEMS, read_oem, read_opm, write_oem
from abrupt.readers.orbit_envelope import check_orbit_envelope
from abrupt.readers.sp3 import KNOWN_TIME_SYSTEMS, read_sp3, write_sp3
from abrupt.series.ephemeris import Ephemeris

EphemerisFormat = Literal["sp3", "oem-kvn", "oem-xml", "opm", "cpf", "csv"]


def sniff_format(path: str | Path) -> EphemerisFormat:
    """The ephemeris format of a file, from its first bytes (after decompression)."""
    head = read_bytes(path)[:4096].decode("latin-1")
    text = head.lstrip("\ufeff\r\n\t ")
    if len(text) > 1 and text[0] == "#" and text[1] in "abcd":
        return "sp3"
    if text.startswith("CCSDS_OEM_VERS"):
        return "oem-kvn"
    if text.startswith("CCSDS_OPM_VERS"):
        return "opm"
    if text.startswith("<"):
        lowered = text.lower()
        if "<oem" in lowered or ":oem" in lowered:
            return "oem-xml"
        raise InputError("XML file is not a CCSDS OEM (<oem> root expected)", file=path, line=1, column=1)
    if text[:2].upper() == "H1" and text[2:].split()[:1] in (["CPF"], ["cpf"]):
        return "cpf"
    first_line = text.splitlines()[0] if text else ""
    if "time_utc" in first_line or Path(path).suffix.lower() == ".csv":
        return "csv"
    raise InputError(
        "unknown ephemeris format (expected SP3, CCSDS OEM/OPM, ILRS CPF or navigation CSV)", file=path, line=1
    )


def read_ephemeris(
    path: str | Path, satellite: str | None = None, *, allow_truncated: bool = False, strict: bool = False
) -> Ephemeris:
    """Read one satellite's ephemeris from any supported orbit file (UTC times, SI units), inside the
    physical envelope of an Earth orbit (:func:`~abrupt.readers.orbit_envelope.check_orbit_envelope`:
    refused or repaired and counted). ``strict``: an SP3 header count the body does not match is an error
    even when the records are complete."""
    fmt = sniff_format(path)
    if fmt == "sp3":
        eph = read_sp3(path, satellite, allow_truncated=allow_truncated, strict=strict)
    elif fmt in ("oem-kvn", "oem-xml"):
        eph = read_oem(path, satellite)
    elif fmt == "opm":
        eph = read_opm(path, satellite)
    elif fmt == "cpf":
        eph = read_cpf(path, satellite, allow_truncated=allow_truncated)
    else:
        eph = read_navigation_csv(path, satellite)
    return check_orbit_envelope(eph)


def write_ephemeris(
    ephemeris: Ephemeris, path: str | Path, *, like: str | Path | None = None, fmt: EphemerisFormat | None = None
) -> EphemerisFormat:
    """Write ``ephemeris`` in ``fmt``, or in the format of the file ``like`` (default: navigation CSV).

    An output name ending in ``.csv`` always gives navigation CSV. SP3 keeps the ephemeris' time system
    when SP3 knows it (GPS otherwise); OEM keeps it when OEM knows it (UTC otherwise). Formats without a
    writer (OPM, CPF) are written as OEM KVN when the states have velocities, else as SP3. Returns the
    format written.
    """
    if fmt is None:
        fmt = "csv" if Path(path).suffix.lower() == ".csv" or like is None else sniff_format(like)
    if fmt in ("opm", "cpf"):
        fmt = "oem-kvn" if np.all(np.isfinite(ephemeris.velocity_mps)) else "sp3"
    if fmt == "sp3":
        ts = ephemeris.time_system if ephemeris.time_system in KNOWN_TIME_SYSTEMS else "GPS"
        write_sp3(ephemeris, path, time_system=ts)
    elif fmt in ("oem-kvn", "oem-xml"):
        ts = ephemeris.time_system if ephemeris.time_system in TIME_SYSTEMS else "UTC"
        write_oem(ephemeris, path, form="xml" if fmt == "oem-xml" else "kvn", time_system=ts)
    else:
        write_navigation_csv(ephemeris, path)
    return fmt
