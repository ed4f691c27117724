"""What the command tells the workers' fork server to warm (preload.py), and where the
server says that it compiles: the one protocol both sides share, light enough for the
command to import (no numba)."""

import os
from pathlib import Path

WARM = "TRACKBENCH_WARM"    # what the fork server's preload warms: JSON {"scenarios": [...], "flag": path}
MAX_WARM = 4


def warm_kinds(scenarios):
    """One scenario dict of each kind of compiled model among a study's runs (solver, track
    layout and method each compile their own time loop; the soil, friction and contact
    options are flags inside it), at most MAX_WARM."""
    kinds = {}
    for d in scenarios:
        kinds.setdefault((d.get("solver"), d.get("track", {}).get("layout"), d.get("method")), d)
    return list(kinds.values())[:MAX_WARM]


def compile_flag():
    """The file where this command's fork server says that it compiles (the progress shows it)."""
    import tempfile
    return Path(tempfile.gettempdir()) / f"trackbench-compiling-{os.getpid()}.json"
