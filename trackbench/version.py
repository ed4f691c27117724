"""Versions: of the package, and of the model (bump MODEL_VERSION when a change to the
model or the solvers changes results: study run ids include it)."""

__version__ = "0.1.0"
MODEL_VERSION = "6"


def toolchain():
    """The versions a run's last bits depend on (docs/development.md, "Bit for bit")."""
    import platform

    import llvmlite
    import numba
    import numpy
    return (f"python {platform.python_version()}, numpy {numpy.__version__}, numba {numba.__version__}, "
            f"llvmlite {llvmlite.__version__}, {platform.machine()}")
