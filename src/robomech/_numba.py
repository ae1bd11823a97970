"""Deferred numba import with robomech's on-disk kernel cache outside the installed package.

numba's ``cache=True`` writes compiled kernels next to the source (``__pycache__`` of the installed
package) unless a cache directory is configured: that is read-only or shared in a system-wide
install, and a cache inside ``site-packages`` outlives the package version.  :func:`import_numba`
points the cache (when the user has not set ``NUMBA_CACHE_DIR``) at ``$XDG_CACHE_HOME/robomech/numba``
(default ``~/.cache/robomech/numba``), in a sub-folder named by a fingerprint of the kernels' source
files (:data:`KERNEL_SOURCES`): numba checks a cached kernel against its own file's time stamp only,
not against the files of the kernels it calls, so an edited or upgraded callee would otherwise leave
its callers' stale machine code in use.  The folder is set through the environment variable before
numba's first import, and through ``numba.config.CACHE_DIR`` when the application imported numba
first (numba reads the variable once, at import, but looks the setting up again whenever a kernel's
cache is opened).

Every compilation (a kernel's first use with empty caches) is announced on the ``robomech`` logger
(``logging.getLogger("robomech")``) at INFO: ``compiling kernel X (first use; cached in DIR)``, then
the time it took.  The first compilation of a process is also a WARNING, which Python prints even
where logging is not configured (its last-resort handler), so that a plain script's first call is
never minutes of silence.  A kernel loaded from the cache is not compiled and says nothing.
"""

from __future__ import annotations

import hashlib
import logging
import os
import sys
import time
from pathlib import Path
from types import ModuleType
from typing import Any

__all__ = ["KERNEL_SOURCES", "cache_dir", "import_numba"]

# Every module of the package that defines numba kernels (relative to the package; a test checks the list
# is complete): their contents name the cache folder, so no kernel is ever loaded compiled against an older
# version of a kernel it calls.
KERNEL_SOURCES = (
    "analysis/_householder.py",
    "mechanisms/spherical_leg/_kinematics.py",
    "multibody/_compiled.py",
    "multibody/_designs.py",
    "multibody/_rnea_kernels.py",
)

_LOG = logging.getLogger("robomech")
_LISTENING = False


def _fingerprint() -> str:
    """The first 16 hex digits of the SHA-256 of the kernel sources (:data:`KERNEL_SOURCES`)."""
    h = hashlib.sha256()
    root = Path(__file__).parent
    for name in KERNEL_SOURCES:
        h.update(name.encode())
        h.update((root / name).read_bytes())
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    """Where robomech's compiled kernels are cached (``NUMBA_CACHE_DIR`` if set; otherwise a folder per
    version of the kernel sources, module docstring)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "robomech" / "numba" / _fingerprint()


def _listen(numba: ModuleType) -> None:
    """Log every numba compilation on the ``robomech`` logger (installed once per process)."""
    global _LISTENING
    if _LISTENING:
        return
    from numba.core import event

    state: dict[str, Any] = {"depth": 0, "t0": 0.0, "name": "", "warned": False}

    class _Listener(event.Listener):
        def on_start(self, ev: Any) -> None:
            state["depth"] += 1
            if state["depth"] == 1:  # a kernel's callees compile inside its own first use
                disp = (ev.data or {}).get("dispatcher")
                name = getattr(getattr(disp, "py_func", None), "__qualname__", "a kernel")
                mod = getattr(getattr(disp, "py_func", None), "__module__", "")
                state["t0"], state["name"] = time.perf_counter(), f"{mod}.{name}" if mod else name
                where = getattr(numba.config, "CACHE_DIR", "")
                if not state["warned"]:
                    state["warned"] = True
                    _LOG.warning(
                        "compiling robomech's kernels, which are not in the cache %s (a new install or "
                        "version, or a cleared cache): each compiles once, in seconds, and is then "
                        "cached; logging at INFO on the 'robomech' logger names each one",
                        where,
                    )
                _LOG.info("compiling kernel %s (first use; cached in %s)", state["name"], where)

        def on_end(self, ev: Any) -> None:
            state["depth"] -= 1
            if state["depth"] == 0:
                _LOG.info("compiled kernel %s in %.1f s", state["name"], time.perf_counter() - state["t0"])

    event.register("numba:compile", _Listener())
    _LISTENING = True


def import_numba() -> ModuleType:
    """``import numba``, with its cache at :func:`cache_dir` and compilations logged (module docstring)."""
    user_set = bool(os.environ.get("NUMBA_CACHE_DIR"))
    if "numba" not in sys.modules and not user_set:
        os.environ["NUMBA_CACHE_DIR"] = str(cache_dir())
    import numba

    if not getattr(numba.config, "CACHE_DIR", ""):  # imported before robomech could set the variable
        setattr(numba.config, "CACHE_DIR", str(cache_dir()))  # noqa: B010 (numba.config is untyped)
    _listen(numba)
    return numba
