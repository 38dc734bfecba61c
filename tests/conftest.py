"""Shared fixtures: the real datasets in ../shared/data (tests skip with a message when absent)."""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from pathlib import Path

import matplotlib
import pytest
from hypothesis import settings

matplotlib.use("Agg")

# In CI the property tests draw the same examples every run (a failure there is reproducible, not luck);
# locally they explore new examples each run.
settings.register_profile("ci", derandomize=True, database=None)
if os.environ.get("CI"):
    settings.load_profile("ci")

PROJECT_ROOT = Path(__file__).resolve().parent.parent
SHARED_DATA = PROJECT_ROOT.parent / "shared" / "data"
# The reproduction testbeds (benchmarks/reproductions) are tested as the benchmarks import them.
sys.path.insert(0, str(PROJECT_ROOT / "benchmarks"))


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The folder of small real datasets beside the project (``../shared/data``)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real datasets not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session")
def postgresql_server_url() -> Iterator[str]:
    """A real PostgreSQL server started for this test session (skips, saying why, where impossible)."""
    try:
        import psycopg  # noqa: F401
    except ImportError:
        pytest.skip("psycopg not installed: pip install -e '.[postgresql]'")
    from pg_server import postgresql_server

    try:
        server = postgresql_server()
        url = server.__enter__()
    except RuntimeError as exc:
        pytest.skip(f"no PostgreSQL server for the catalog tests: {exc}")
    try:
        yield url
    finally:
        server.__exit__(None, None, None)


@pytest.fixture(params=["sqlite", "postgresql"])
def catalog_target(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    """An empty catalog on each back-end: a SQLite file path, or a new database on a real server."""
    if request.param == "sqlite":
        return str(tmp_path / "catalog.sqlite")
    from pg_server import new_database

    return new_database(request.getfixturevalue("postgresql_server_url"))
