"""Numba's disk cache keyed on every source its compiled kernels depend on.

``@njit(cache=True)`` stamps a cached kernel with the content of the file that defines it, and nothing
else. A kernel that calls a jitted function of another module, or reads a constant imported from one,
compiles that callee or value into its own machine code; when only the other module changes, numba
still loads the old code. :func:`use_keyed_numba_cache` points ``NUMBA_CACHE_DIR`` at a folder named
after a hash of :data:`JIT_SOURCES` (the modules that use numba and every module whose jitted
functions, numbers or arrays they import), so any change to one of them starts a fresh cache and an
unchanged tree reuses its own. ``tests/test_jit_cache.py`` derives the dependency set from the import
statements and fails naming any module missing here.

A ``NUMBA_CACHE_DIR`` already set (by the user, or by a parent abrupt process) is kept as it is.
Folders of older source states are not removed (each is a few MB; delete ``~/.cache/abrupt`` freely).
"""

from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

#: Package-relative paths of the sources numba's compiled kernels depend on.
JIT_SOURCES: tuple[str, ...] = (
    "clean/rolling_median.py",
    "density/window_scan.py",
    "detect/attitude/change_detection.py",
    "detect/orbit/glr.py",
    "detect/orbit/kernels.py",
    "detect/orbit/statistics.py",
    "detect/tle/step_kernels.py",
    "model/atmosphere.py",
    "model/attitude_dynamics.py",
    "model/attitude_kernels.py",
    "model/msis_grid.py",
    "model/orbit/__init__.py",
    "model/orbit/batch_fit.py",
    "model/orbit/constants.py",
    "model/orbit/eclipses.py",
    "model/orbit/forces.py",
    "model/orbit/gravity.py",
    "model/orbit/propagation.py",
    "model/orbit/small_forces.py",
    "model/tracking_measurements.py",
    "rates/geometry.py",
    "units.py",
)

PACKAGE_ROOT = Path(__file__).resolve().parent


def sources_key(root: Path, sources: tuple[str, ...]) -> str:
    """A 16-hex-digit SHA-256 of the names and contents of ``sources`` below ``root`` (a missing file
    counts as empty, so the key still changes when it appears)."""
    digest = hashlib.sha256()
    for rel in sources:
        path = root / rel
        digest.update(rel.encode() + b"\0")
        digest.update(path.read_bytes() if path.is_file() else b"")
        digest.update(b"\0")
    return digest.hexdigest()[:16]


def keyed_cache_dir(base: Path, version: str, key: str) -> Path:
    """The cache folder of one source state: ``base/numba-<version>-<key>``."""
    return base / f"numba-{version}-{key}"


def default_cache_base() -> Path | None:
    """``$XDG_CACHE_HOME/abrupt`` or ``~/.cache/abrupt``; None when there is no home to put it in."""
    if xdg := os.environ.get("XDG_CACHE_HOME"):
        return Path(xdg) / "abrupt"
    try:
        return Path.home() / ".cache" / "abrupt"
    except RuntimeError:
        return None


def use_keyed_numba_cache(version: str) -> None:
    """Set ``NUMBA_CACHE_DIR`` to the folder of the installed sources' state, unless it is already set;
    when numba is already imported its configuration is updated too (never importing numba here)."""
    if os.environ.get("NUMBA_CACHE_DIR") or (base := default_cache_base()) is None:
        return
    try:
        key = sources_key(PACKAGE_ROOT, JIT_SOURCES)
    except OSError:  # sources unreadable (a zipped install): numba's own per-file stamps stay in force
        return
    folder = str(keyed_cache_dir(base, version, key))
    os.environ["NUMBA_CACHE_DIR"] = folder
    if (config := sys.modules.get("numba.core.config")) is not None:
        config.CACHE_DIR = folder  # type: ignore[attr-defined]
