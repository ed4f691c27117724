"""Vehicles as data: one TOML file per vehicle, the catalogue shipped here (lee2000.toml, the
paper's vehicle) and any file a user writes. A file holds the scenario's own names
(vehicle.*, track.*, sprocket.*, idler.*, rollers.*) and a [source] table that cites every
number. This package reads files and knows their shape; it imports nothing else of the
package: the scenario (scenario/vehicle_model.py) checks the values and applies them."""

from .loader import (
    GROUPS,
    REFERENCE,
    VehicleError,
    VehicleFile,
    catalogue,
    catalogue_path,
    known_names,
    locate,
    read,
)

__all__ = ["GROUPS", "REFERENCE", "VehicleError", "VehicleFile", "catalogue", "catalogue_path",
           "known_names", "locate", "read"]
