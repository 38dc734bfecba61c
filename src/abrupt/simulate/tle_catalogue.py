"""A simulated public catalogue: many maneuver-free TLE histories at the catalogue's mix, on disk.

The public catalogue (Space-Track/CelesTrak, 2024-2025) holds about 25,000 objects in orbit and
publishes about 9 million element sets a year for them, close to one set per object per day on
average. Most objects are in LEO; a large constellation shell near 550 km is tracked at about two sets
a day, the bulk of the LEO debris and payloads at about one, sparsely tracked small debris at one
every two days, and the deep-space population (GEO and, lumped with it here, MEO and HEO, which the
null generator has no model of) at about one set a day. :data:`CATALOGUE_MIX` states the fractions,
altitudes, inclinations and cadences used; :func:`catalogue_specs` draws one
:class:`~abrupt.simulate.tle_null.NullHistorySpec` per object from it (seeded), and
:func:`write_catalogue` writes the histories as 2-line TLE files of ``objects_per_file`` objects each,
one file at a time (memory does not grow with the number of objects).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from sgp4.exporter import export_tle

from abrupt.readers.tle import ElementHistory, tle_checksum
from abrupt.simulate.tle_null import NullHistorySpec, simulate_null_history

FIRST_NORAD = 10000  # simulated catalog numbers: FIRST_NORAD + object index (five digits up to 89,999 objects)


@dataclass(frozen=True)
class CatalogueClass:
    """One population of the catalogue mix (units in the names)."""

    name: str
    fraction: float
    regime: str
    altitude_km: tuple[float, float]
    inclinations_deg: tuple[float, ...]
    sets_per_day: float


CATALOGUE_MIX: tuple[CatalogueClass, ...] = (
    CatalogueClass("constellation shell", 0.30, "leo", (540.0, 560.0), (53.0, 43.0, 70.0, 97.6), 1.8),
    CatalogueClass("LEO payloads and debris", 0.40, "leo", (600.0, 1000.0), (98.0, 82.0, 65.0, 74.0), 0.8),
    CatalogueClass("sparse small debris", 0.18, "leo", (450.0, 1400.0), (98.0, 86.0, 71.0, 28.5), 0.5),
    CatalogueClass("deep space (GEO; MEO/HEO lumped)", 0.12, "geo", (35786.0, 35786.0), (0.0,), 0.7),
)


def mean_sets_per_day(mix: tuple[CatalogueClass, ...] = CATALOGUE_MIX) -> float:
    """Element sets per object per day of the mix (before the generator's gaps)."""
    return float(sum(c.fraction * c.sets_per_day for c in mix))


def catalogue_specs(
    n_objects: int, *, years: float = 1.0, seed: int = 0, mix: tuple[CatalogueClass, ...] = CATALOGUE_MIX
) -> Iterator[NullHistorySpec]:
    """One seeded null-history spec per object, drawn from ``mix`` (object ``k`` has seed ``seed + k``).

    The class of object ``k`` is a deterministic stratified draw, so any prefix of the catalogue
    keeps the mix's fractions to within one object per class.
    """
    if n_objects < 1:
        raise ValueError(f"n_objects must be >= 1, got {n_objects}")
    fractions = np.array([c.fraction for c in mix], dtype=float)
    fractions /= fractions.sum()
    counts = np.zeros(len(mix))
    for k in range(n_objects):
        cls = mix[int(np.argmax(fractions * (k + 1) - counts))]  # the class most behind its share
        counts[mix.index(cls)] += 1
        rng = np.random.default_rng((seed, k))
        yield NullHistorySpec(
            regime=cls.regime,
            years=years,
            sets_per_day=cls.sets_per_day,
            altitude_km=float(rng.uniform(*cls.altitude_km)),
            inclination_deg=float(rng.choice(cls.inclinations_deg)) if cls.regime == "leo" else 98.0,
            seed=seed + k,
        )


def tle_lines(history: ElementHistory, norad_id: int) -> Iterator[str]:
    """The history as 2-line element sets under catalog number ``norad_id`` (checksums recomputed)."""
    if not 0 < norad_id < 100000:
        raise ValueError(f"catalog number {norad_id} does not fit the five columns of a TLE")
    for sat in history.satrecs:
        for line in export_tle(sat):
            body = line[:2] + f"{norad_id:05d}" + line[7:68]
            yield body + str(tle_checksum(body))


def write_catalogue(
    folder: str | Path,
    n_objects: int,
    *,
    objects_per_file: int = 50,
    years: float = 1.0,
    seed: int = 0,
) -> list[Path]:
    """Write ``n_objects`` simulated histories as TLE files ``catalogue-00000.tle``, ... in ``folder``.

    Files already present with the same name are rewritten. Returns the file paths in order.
    """
    if objects_per_file < 1:
        raise ValueError(f"objects_per_file must be >= 1, got {objects_per_file}")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    fh = None
    try:
        for k, spec in enumerate(catalogue_specs(n_objects, years=years, seed=seed)):
            if k % objects_per_file == 0:
                if fh is not None:
                    fh.close()
                paths.append(folder / f"catalogue-{k // objects_per_file:05d}.tle")
                fh = paths[-1].open("w", encoding="ascii")
            history = simulate_null_history(spec)
            assert fh is not None
            fh.write("\n".join(tle_lines(history, FIRST_NORAD + k)) + "\n")
    finally:
        if fh is not None:
            fh.close()
    return paths
