"""The event catalog: events, runs and resumable work in a SQL database (docs/catalog.md).

:mod:`abrupt.catalog.database` holds :class:`Catalog`; :mod:`abrupt.catalog.schema` its tables and
the upgrade of old catalogs; :mod:`abrupt.catalog.foreign` the refusal of tables abrupt did not create.
"""

from abrupt.catalog.database import (
    Added,
    AnalysedSpan,
    Catalog,
    CatalogError,
    Coverage,
    catalog_url,
    coverage_of,
    run_key,
)
from abrupt.catalog.schema import coverage_table, event_key

__all__ = [
    "Added",
    "AnalysedSpan",
    "Catalog",
    "CatalogError",
    "Coverage",
    "catalog_url",
    "coverage_of",
    "coverage_table",
    "event_key",
    "run_key",
]
