"""Atomic file writes, for every file trackbench writes (netCDF, recordings, JSON, tables):
the content goes to a temporary name in the target's folder (".<name>.<random>.tmp") and is
renamed into place only when complete, so a killed or failed writer never leaves a file
that looks complete, and a reader holding the old file keeps it."""

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

TMP_SUFFIX = ".tmp"


def tmp_path(path):
    """A fresh temporary name beside ``path`` (its folder is created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + path.name + ".", suffix=TMP_SUFFIX, dir=path.parent)
    os.close(fd)
    return tmp


def _umask():
    m = os.umask(0)
    os.umask(m)
    return m


@contextmanager
def atomic_path(path):
    """Yield a temporary path; on success rename it onto ``path`` with the mode an ordinary
    open() would give it (mkstemp makes 0600), on any failure (KeyboardInterrupt too)
    remove it."""
    tmp = tmp_path(path)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.truncate(tmp, 0)   # frees its space even when a failed writer still holds it open
            os.remove(tmp)
        raise


def writable_folder(path):
    """Make sure ``path`` is a folder this process can write files into (created when missing),
    before any work starts; raises ValueError with one line naming the path and the problem."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{path} is a file, not a folder: give a folder path")
    parent = Path(os.path.abspath(path))
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise ValueError(f"{path} cannot be created: {parent} is a file, not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise ValueError(f"{path} cannot be created in {parent}: {e.strerror or e}") from None
    try:
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as e:
        raise ValueError(f"{path} is not writable: {e.strerror or e}") from None
    return path
