"""Every file is written atomically: a writer that fails midway leaves neither the target
nor a temporary file."""

import os

import pytest

from trackbench.outputs.files.atomic import atomic_path


def test_failed_writer_leaves_nothing(tmp_path):
    target = tmp_path / "sub" / "result.nc"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            with open(tmp, "w") as f:
                f.write("half a file")
            raise RuntimeError("disk trouble")
    assert not target.exists()
    assert os.listdir(target.parent) == []


def test_complete_file_lands_with_the_usual_mode(tmp_path):
    target = tmp_path / "result.txt"
    target.write_text("old")
    with atomic_path(target) as tmp:
        with open(tmp, "w") as f:
            f.write("new")
    assert target.read_text() == "new"
    assert os.listdir(tmp_path) == ["result.txt"]
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~umask
