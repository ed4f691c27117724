"""What the command tells the workers' fork server to warm, and where the server says that it
compiles: the one protocol both sides share (forkserver.py the command's side, preload.py the
server's), light enough for the command to import (no numba).

The command starts the server before it reads the study file, so the server cannot be told
on its command line which kinds of model the runs need: it is told LATER, through
warm_file(), which the command writes (announce) once it knows the runs, and which the
server waits for after its imports."""

import json
import os
from pathlib import Path

WARM = "TRACKBENCH_WARM"    # the server's spec (JSON): {"scenarios": [...]} or {"file": path}; "flag"
MAX_WARM = 4
LATER = "later"             # start_workers(warm=LATER): the kinds come through warm_file()
TINY = {"duration": 1e-3, "output_interval": 1e-3}   # the run that loads a kind's kernels


def warm_kinds(scenarios):
    """One scenario dict of each kind of compiled model among a study's runs (solver, track
    layout and method each compile their own time loop; the soil, friction and contact
    options are flags inside it), at most MAX_WARM."""
    kinds = {}
    for d in scenarios:
        kinds.setdefault((d.get("solver"), d.get("track", {}).get("layout"), d.get("method")), d)
    return list(kinds.values())[:MAX_WARM]


def _tmp(kind):
    import tempfile
    return Path(tempfile.gettempdir()) / f"trackbench-{kind}-{os.getpid()}.json"


def compile_flag():
    """The file where this command's fork server says that it compiles (the progress shows it)."""
    return _tmp("compiling")


def warm_file():
    """The file through which this command tells a server started with LATER what to warm."""
    return _tmp("warm")


def spec(warm):
    """The server's WARM spec for start_workers(warm=...): a list of scenario dicts, or LATER."""
    if warm == LATER:
        warm_file().unlink(missing_ok=True)   # a file of an earlier process of the same pid
        return {"file": str(warm_file()), "flag": str(compile_flag())}
    return {"scenarios": warm, "flag": str(compile_flag())}


def announce(scenarios):
    """Tell the server what to warm (a list of scenario dicts; [] for nothing) when it waits for
    it (started with LATER); a no-op otherwise, or once said."""
    said = json.loads(os.environ.get(WARM) or "{}")
    path = said.get("file")
    if not path or os.path.exists(path):
        return
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w") as f:
        json.dump({"scenarios": scenarios}, f)
    os.replace(tmp, path)   # whole or not at all: the server reads it as soon as it appears


def _told_later():
    """Was the server of this process started with LATER (it waits for warm_file())?"""
    return "file" in json.loads(os.environ.get(WARM) or "{}")


def forget():
    """Remove this command's files of the protocol (at its end). A server started again later
    in this process (a long-lived one: a notebook, tests) then warms the paper's model instead
    of waiting for a file no one will write."""
    for p in (compile_flag(), warm_file()):
        p.unlink(missing_ok=True)
    if _told_later():
        os.environ.pop(WARM, None)
