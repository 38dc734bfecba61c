"""Importer for NASA ORDEM 3.x spacecraft-mode output (and MASTER-like text tables) into a flux table.

ORDEM 3.x in spacecraft mode writes plain-text tables: a cumulative flux against size, split by
population (intacts, NaK, low-, medium- and high-density fragments) with its uncertainty, and an
"igloo" of flux by azimuth, elevation and speed bins (Bennett 2022 §5.3.3; spec §6.5, §7). Their exact
layout differs between releases, so this reader is keyed on the words of the header line rather than
on column positions:

* **size file**: a column whose header contains ``size`` (metres; ``cm``/``mm``/``um`` in the header
  scale it), one column per population recognised by ``nak``, ``low``, ``med``, ``high``, ``intact``
  (intacts are counted with the high-density class unless ``intact_class`` says otherwise), or a
  ``total`` column when there is no split; uncertainty columns contain ``sigma`` (1-sigma) or
  ``upper``/``lower`` (the 2-sigma bounds; sigma = (upper - lower)/4), either per population or total.
* **igloo file**: columns containing ``az``, ``el``, ``vel`` or ``speed`` (km/s), and ``flux``; values
  are bin centres (widths from the spacing of distinct values) or ``_lo``/``_hi`` pairs.

Lines before the header and lines starting with ``#``, ``!`` or ``*`` are skipped; values may be
separated by spaces, tabs or commas. Anything it cannot read raises :class:`~abrupt.errors.InputError`
naming the file, line, column and reason; :func:`describe_mapping` says how each column was understood.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from abrupt.errors import InputError
from abrupt.rates.tables import DirectionBins, FluxTable

_SPLIT = re.compile(r"[,\s]+")
_SIZE_UNITS = {"um": 1e-6, "micron": 1e-6, "mm": 1e-3, "cm": 1e-2, "(m)": 1.0, "[m]": 1.0}
_CLASS_KEYS = (("nak", "nak"), ("low", "low"), ("med", "medium"), ("high", "high"), ("intact", "intact"))


def _is_number(tok: str) -> bool:
    try:
        float(tok)
    except ValueError:
        return False
    return True


def read_numeric_table(path: Path) -> tuple[list[str], NDArray[np.float64], list[int]]:
    """(header names, numeric rows, file line of each row) of an ORDEM/MASTER-style whitespace table."""
    try:
        lines = path.read_text(errors="replace").splitlines()
    except OSError as exc:
        raise InputError(f"cannot read: {exc.strerror}", file=path) from None
    header: list[str] | None = None
    header_line = 0
    rows: list[list[float]] = []
    line_nos: list[int] = []
    for i, raw in enumerate(lines, start=1):
        text = raw.strip()
        if not text or text[0] in "#!*":
            continue
        toks = [t for t in _SPLIT.split(text) if t]
        if all(_is_number(t) for t in toks):
            if header is None:
                raise InputError("numbers before any header line", file=path, line=i)
            if len(toks) != len(header):
                raise InputError(
                    f"expected {len(header)} values (header line {header_line}), got {len(toks)}",
                    file=path,
                    line=i,
                )
            values = [float(t) for t in toks]
            bad = [k for k, v in enumerate(values) if not math.isfinite(v)]
            if bad:
                raise InputError("value is not finite", file=path, line=i, column=header[bad[0]])
            rows.append(values)
            line_nos.append(i)
        elif not rows:
            header = [t.lower() for t in toks]
            header_line = i
        else:
            raise InputError(f"unexpected text in the table: {text[:40]!r}", file=path, line=i)
    if header is None or not rows:
        raise InputError("empty table: no header or no numeric rows", file=path)
    return header, np.array(rows, dtype=np.float64), line_nos


def _class_of(name: str) -> str | None:
    name = name.replace("lower", "").replace("upper", "")
    for key, cls in _CLASS_KEYS:
        if key in name:
            return cls
    return None


def describe_mapping(header: list[str]) -> dict[str, str]:
    """How each header word of a size file is understood (for the user to check)."""
    out = {}
    for h in header:
        cls = _class_of(h)
        if "size" in h or "diam" in h:
            out[h] = "size"
        elif "sigma" in h or "upper" in h or "lower" in h:
            out[h] = f"uncertainty of {cls or 'total'}"
        elif cls is not None:
            out[h] = f"flux of class {cls}"
        elif "total" in h:
            out[h] = "total flux"
        else:
            out[h] = "ignored"
    return out


def read_ordem_size(
    path: str | Path, *, intact_class: str = "high"
) -> tuple[NDArray[np.float64], tuple[str, ...], NDArray[np.float64], NDArray[np.float64]]:
    """Read an ORDEM-style cumulative flux-vs-size table: sizes [m], classes, flux (C, K), sigma (C, K)."""
    path = Path(path)
    header, data, line_nos = read_numeric_table(path)
    mapping = describe_mapping(header)
    size_cols = [i for i, h in enumerate(header) if mapping[h] == "size"]
    if len(size_cols) != 1:
        raise InputError(f"need exactly one size column, found {len(size_cols)} in header {header}", file=path)
    scol = size_cols[0]
    scale = next((f for u, f in _SIZE_UNITS.items() if u in header[scol]), 1.0)
    sizes = data[:, scol] * scale
    if np.any(sizes <= 0):
        k = int(np.argmax(sizes <= 0))
        raise InputError("size must be positive", file=path, line=line_nos[k], column=header[scol])
    order = np.argsort(sizes)
    if np.any(np.diff(sizes[order]) == 0):
        k = int(order[np.argmax(np.diff(sizes[order]) == 0) + 1])
        raise InputError("duplicate size", file=path, line=line_nos[k], column=header[scol])
    flux_cols: dict[str, list[int]] = {}
    sigma_cols: dict[str, list[tuple[int, str]]] = {}
    total_col = None
    for i, h in enumerate(header):
        m = mapping[h]
        if m.startswith("flux of class"):
            cls = _class_of(h) or "medium"
            cls = intact_class if cls == "intact" else cls
            flux_cols.setdefault(cls, []).append(i)
        elif m.startswith("uncertainty"):
            cls = _class_of(h) or "total"
            cls = intact_class if cls == "intact" else cls
            kind = "sigma" if "sigma" in h else ("upper" if "upper" in h else "lower")
            sigma_cols.setdefault(cls, []).append((i, kind))
        elif m == "total flux":
            total_col = i
    if not flux_cols:
        if total_col is None:
            raise InputError(f"no flux column recognised in header {header}", file=path)
        flux_cols = {"medium": [total_col]}
        sigma_cols = {"medium" if k == "total" else k: v for k, v in sigma_cols.items()}
    classes = tuple(flux_cols)
    flux = np.array([data[:, cols].sum(axis=1) for cols in flux_cols.values()])[:, order]
    for c, cols in enumerate(flux_cols.values()):
        neg = flux[c] < 0
        if np.any(neg):
            raise InputError(
                "flux must not be negative",
                file=path,
                line=line_nos[int(order[np.argmax(neg)])],
                column=header[cols[0]],
            )
        rises = np.diff(flux[c]) > flux[c, :-1] * 1e-9
        if np.any(rises):
            k = int(order[np.argmax(rises) + 1])
            raise InputError("cumulative flux increases with size", file=path, line=line_nos[k], column=header[cols[0]])
    sigma = np.zeros_like(flux)

    def _sig(cols: list[tuple[int, str]]) -> NDArray[np.float64]:
        d = {kind: data[:, i][order] for i, kind in cols}
        if "sigma" in d:
            return d["sigma"]
        if "upper" in d and "lower" in d:
            return (d["upper"] - d["lower"]) / 4.0
        raise InputError("uncertainty needs a sigma column or both upper and lower bounds", file=path)

    for c, cls in enumerate(classes):
        if cls in sigma_cols:
            sigma[c] = _sig(sigma_cols[cls])
    if "total" in sigma_cols:
        tot = flux.sum(axis=0)
        share = np.divide(flux, tot, out=np.zeros_like(flux), where=tot > 0)
        sigma = np.where(sigma == 0, share * _sig(sigma_cols["total"]), sigma)
    if np.any(sigma < 0):
        raise InputError("negative uncertainty (upper bound below lower?)", file=path)
    return sizes[order], classes, flux, sigma


def read_ordem_igloo(path: str | Path) -> DirectionBins:
    """Read an ORDEM-style igloo table of flux by azimuth, elevation [deg] and speed [km/s]."""
    path = Path(path)
    header, data, line_nos = read_numeric_table(path)

    def find(key: str, exclude: tuple[str, ...] = ()) -> list[int]:
        return [i for i, h in enumerate(header) if key in h and not any(x in h for x in exclude)]

    flux_c = find("flux")
    if len(flux_c) != 1:
        raise InputError(f"need exactly one flux column in header {header}", file=path)
    f = data[:, flux_c[0]]
    if np.any(f < 0):
        raise InputError(
            "flux must not be negative",
            file=path,
            line=line_nos[int(np.argmax(f < 0))],
            column=header[flux_c[0]],
        )
    if not f.sum() > 0:
        raise InputError("igloo has zero total flux", file=path)

    def bounds(
        keys: tuple[str, ...], default: tuple[float, float] | None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        cols = [i for k in keys for i in find(k, ("flux",))]
        cols = sorted(set(cols))
        if not cols:
            if default is None:
                raise InputError(f"no {keys[0]} column in header {header}", file=path)
            n = data.shape[0]
            return np.full(n, default[0]), np.full(n, default[1])
        lo_c = [i for i in cols if "lo" in header[i] or "min" in header[i]]
        hi_c = [i for i in cols if "hi" in header[i] or "max" in header[i]]
        if lo_c and hi_c:
            return data[:, lo_c[0]], data[:, hi_c[0]]
        centre = data[:, cols[0]]
        distinct = np.unique(centre)
        width = float(np.min(np.diff(distinct))) if distinct.size > 1 else 0.0
        return centre - width / 2, centre + width / 2

    az_lo, az_hi = bounds(("az",), None)
    el_lo, el_hi = bounds(("el",), (0.0, 0.0))
    v_lo, v_hi = bounds(("vel", "speed"), None)
    if np.any(v_lo <= 0) or np.any(v_hi > 100.0):
        k = int(np.argmax((v_lo <= 0) | (v_hi > 100.0)))
        raise InputError("speeds must be in (0, 100] km/s", file=path, line=line_nos[k])
    el_lo, el_hi = np.clip(el_lo, -90.0, 90.0), np.clip(el_hi, -90.0, 90.0)
    d2r = math.pi / 180.0
    keep = f > 0
    return DirectionBins(
        v_lo[keep] * 1e3,
        v_hi[keep] * 1e3,
        az_lo[keep] * d2r,
        az_hi[keep] * d2r,
        el_lo[keep] * d2r,
        el_hi[keep] * d2r,
        f[keep] / f[keep].sum(),
    )


def import_ordem(
    size_path: str | Path,
    igloo_path: str | Path,
    *,
    name: str = "ORDEM",
    altitude_km: float = float("nan"),
    inclination_deg: float = float("nan"),
    epoch_year: float = float("nan"),
    flux_convention: str = "cross_section",
    intact_class: str = "high",
) -> FluxTable:
    """Build a :class:`FluxTable` from ORDEM 3.x spacecraft-mode size and igloo tables."""
    sizes, classes, flux, sigma = read_ordem_size(size_path, intact_class=intact_class)
    if flux_convention == "tumbling":
        flux, sigma = 4 * flux, 4 * sigma
    elif flux_convention != "cross_section":
        raise InputError("flux_convention must be 'cross_section' or 'tumbling'", file=size_path)
    return FluxTable(
        name=name,
        sizes_m=sizes,
        classes=classes,
        cumulative_flux=flux,
        cumulative_sigma=sigma,
        directions=read_ordem_igloo(igloo_path),
        altitude_m=altitude_km * 1e3,
        inclination_deg=inclination_deg,
        epoch_year=epoch_year,
    )
