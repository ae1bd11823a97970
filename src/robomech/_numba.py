"""Deferred numba import with robomech's on-disk kernel cache outside the installed package.

numba's ``cache=True`` writes compiled kernels next to the source (``__pycache__`` of the installed
package) unless ``NUMBA_CACHE_DIR`` is set: that is read-only or shared in a system-wide install, and
a cache inside ``site-packages`` outlives the package version.  Before the first numba import this
points ``NUMBA_CACHE_DIR`` (when the user has not set it) at ``$XDG_CACHE_HOME/robomech/numba``
(default ``~/.cache/robomech/numba``).  numba reads the variable once, at import: if numba was already
imported by the application, its own setting stays.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from types import ModuleType

__all__ = ["cache_dir", "import_numba"]


def cache_dir() -> Path:
    """Where robomech's compiled kernels are cached (``NUMBA_CACHE_DIR`` if set)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "robomech" / "numba"


def import_numba() -> ModuleType:
    """``import numba``, after pointing its cache at :func:`cache_dir` (see the module docstring)."""
    if "numba" not in sys.modules and not os.environ.get("NUMBA_CACHE_DIR"):
        os.environ["NUMBA_CACHE_DIR"] = str(cache_dir())
    import numba

    return numba
