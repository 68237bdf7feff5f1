"""What a run records per vehicle: one list of fields, with units.

The log's ``/cosim/vehicles`` schema, the CSV export's columns, the
in-memory vehicle table of :class:`cosim.core.simulation.SimulationResult`
and the scenario-testing results all derive from :data:`VEHICLE_FIELDS`;
adding a field here adds it everywhere. A contact point's id names its vehicle
and axle (:func:`vehicle_of`); this module loads nothing heavy, so log readers use it.
"""
from __future__ import annotations

from dataclasses import dataclass

#: Between a vehicle's id and its axle's number in a contact point's id (``"truck7#2"``).
AXLE_SEPARATOR = "#"


def vehicle_of(contact_id: str) -> str:
    """The vehicle a contact point belongs to: ``"truck7#2"`` (axle 2 of truck7) -> ``"truck7"``."""
    return contact_id.split(AXLE_SEPARATOR, 1)[0]


@dataclass(frozen=True)
class Field:
    """One recorded quantity: its name, SI unit ("" for text), description and JSON type."""

    name: str
    unit: str
    description: str
    json_type: str = "number"


#: Per vehicle (contact point) and sample, in the order of the log schema and the CSV columns.
VEHICLE_FIELDS: tuple[Field, ...] = (
    Field("id", "", "vehicle (contact point) id; axle k of a multi-axle vehicle is '<vehicle>#<k>'", "string"),
    Field("model", "", "vehicle model", "string"),
    Field("x", "m", "contact point along the axis"),
    Field("y", "m", "lateral offset"),
    Field("speed", "m/s", "along +x"),
    Field("acceleration", "m/s^2", "along +x"),
    Field("body_displacement", "m", "from static equilibrium"),
    Field("body_acceleration", "m/s^2", "vertical, of the body"),
    Field("contact_force", "N", "wheel on deck, compression positive"),
)

#: The numeric fields (every field but the id and the model), in order.
VEHICLE_NUMBERS: tuple[str, ...] = tuple(f.name for f in VEHICLE_FIELDS if f.json_type == "number")
