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
import tempfile
import warnings
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
KEY_VARIABLE = "ABRUPT_NUMBA_KEY"  # the source state an inherited NUMBA_CACHE_DIR was keyed on


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


def writable_folder(folder: Path) -> bool:
    """True when ``folder`` exists or can be created and a file can be written in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder):
            pass
    except OSError:
        return False
    return True


def use_keyed_numba_cache(version: str) -> None:
    """Set ``NUMBA_CACHE_DIR`` to the folder of the installed sources' state.

    A ``NUMBA_CACHE_DIR`` set by the user is kept; one set by an abrupt process of another source state
    (its ``ABRUPT_NUMBA_KEY`` differs, e.g. a child started from another checkout) is replaced. When the
    home cache cannot be written, a per-user folder under the system's temporary directory is used and one
    warning says so; when neither can be written, numba's own per-file stamps stay in force, also said.
    When numba is already imported its configuration is updated too (never importing numba here).
    Side effect: other numba code in the same process caches in this folder too.
    """
    inherited_key = os.environ.get(KEY_VARIABLE)
    if os.environ.get("NUMBA_CACHE_DIR") and inherited_key is None:
        return
    try:
        source_hash = sources_key(PACKAGE_ROOT, JIT_SOURCES)
    except OSError:  # sources unreadable (a zipped install): numba's own per-file stamps stay in force
        return
    key = f"{version}-{source_hash}"
    if os.environ.get("NUMBA_CACHE_DIR") and inherited_key == key:
        return
    user = os.getuid() if hasattr(os, "getuid") else 0
    bases = [b for b in (default_cache_base(), Path(tempfile.gettempdir()) / f"abrupt-{user}") if b is not None]
    candidates = [keyed_cache_dir(base, version, source_hash) for base in bases]
    folder = next((c for c in candidates if writable_folder(c)), None)
    if folder is None:
        warnings.warn(
            f"abrupt: no writable numba cache folder ({', '.join(map(str, candidates))}); compiled kernels are "
            "cached beside the sources, keyed by each file only",
            RuntimeWarning,
            stacklevel=2,
        )
        return
    if folder != candidates[0]:
        warnings.warn(
            f"abrupt: {candidates[0]} cannot be written; numba kernels are cached in {folder}",
            RuntimeWarning,
            stacklevel=2,
        )
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    os.environ[KEY_VARIABLE] = key
    if (config := sys.modules.get("numba.core.config")) is not None:
        config.CACHE_DIR = str(folder)  # type: ignore[attr-defined]
