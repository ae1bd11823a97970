"""The kernel cache folder follows the kernel sources, so no cached kernel outlives a callee's edit."""

import re
import shutil
from pathlib import Path

import pytest

import robomech
from robomech import _numba

PACKAGE = Path(robomech.__file__).parent
KERNEL = re.compile(r"@_nj\b|@numba\.njit|\bnjit\(|\b_nj\(")


def test_every_kernel_module_is_in_the_fingerprint():
    defining = sorted(
        str(p.relative_to(PACKAGE))
        for p in PACKAGE.rglob("*.py")
        if KERNEL.search(p.read_text(encoding="utf-8"))
    )
    assert defining == sorted(_numba.KERNEL_SOURCES)


def test_cache_folder_changes_with_any_kernel_source(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    copy = tmp_path / "robomech"
    for name in _numba.KERNEL_SOURCES:
        (copy / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(PACKAGE / name, copy / name)
    monkeypatch.setattr(_numba, "__file__", str(copy / "_numba.py"))
    before = _numba.cache_dir()
    assert before.parent == tmp_path / "cache" / "robomech" / "numba"
    assert _numba.cache_dir() == before  # deterministic
    for name in _numba.KERNEL_SOURCES:
        src = copy / name
        text = src.read_bytes()
        src.write_bytes(text + b"\n# edited\n")
        assert _numba.cache_dir() != before, name
        src.write_bytes(text)
    assert _numba.cache_dir() == before


def test_user_cache_folder_is_kept(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    assert _numba.cache_dir() == tmp_path


@pytest.mark.parametrize("name", _numba.KERNEL_SOURCES)
def test_kernel_sources_exist(name):
    assert (PACKAGE / name).is_file()
