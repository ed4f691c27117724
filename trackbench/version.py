"""Versions: of the package, and of the model (bump MODEL_VERSION when a change to the
model or the solvers changes results: study run ids include it)."""

__version__ = "0.1.0"
MODEL_VERSION = "2"
