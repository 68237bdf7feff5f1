"""Each SUMO vehicle's own loads, from a WIM-calibrated model (``[traffic.loads]``; docs/loads.md).

SUMO makes the traffic move; Grave's model (:mod:`cosim.core.loads`) makes it
weigh like a real site's. When a vehicle is first seen, :class:`VehicleLoads`
decides what it carries, from the scenario's seed and the vehicle's id only
(so the same vehicle carries the same loads in any process, run, replay or
study):

- a vType of a heavy vClass (truck, trailer, bus, coach, delivery), or one
  mapped to truck classes by ``vtype_classes``: a truck of a class drawn from
  the site's class mix for its direction, restricted to the classes that fit
  the vType's length (see :func:`classes_for`), with that class's gross weight,
  axle spacings and axle loads (each direction its own parameters);
- a car (passenger, private, taxi, evehicle vClasses, or ``"car"``): the light
  distribution's two axles and weight;
- anything else (``"fixed"``, other vClasses, a vType whose ``cosim.*`` params or
  ``mass`` set its own weights and is not mapped): the vType's own model.

A drawn vehicle keeps its vType's suspension (its frequencies and damping
ratios: the vType's model scaled to the drawn weight), its front axle where
the vType has it (else :data:`FRONT_OVERHANG` behind the bumper, within the
vehicle), and its axles on the vehicle: a wheelbase longer than the vType
allows (its length less the overhangs) is shortened to fit, which the record
says ("spacings scaled to the vType"). Each vehicle also gets its lateral
wander (EN 1991-2 Figure 4.6, or normal), from its own stream.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

from cosim.core.loads import CLASSES, GraveModel, VehicleLoad, draw_car, lane_wander, uniforms

from .vtypes import VehicleType, loaded_vehicle_type

__all__ = ["FRONT_OVERHANG", "HEAVY_CLASSES", "LIGHT_VCLASSES", "LoadSettings", "VehicleDraw", "VehicleLoads",
           "classes_for"]

#: The truck classes (axle counts) a heavy vClass draws from unless ``vtype_classes`` says otherwise.
HEAVY_CLASSES: dict[str, tuple[int, ...]] = {
    "truck": (2, 3), "trailer": (4, 5), "bus": (2, 3), "coach": (2, 3), "delivery": (2,),
}
#: vClasses that draw from the light (car) distribution.
LIGHT_VCLASSES = ("passenger", "private", "taxi", "evehicle")
#: The front axle's distance behind the bumper when the vType does not place one (a vehicle with one contact
#: point at mid-length), m; and the least rear overhang a drawn wheelbase leaves, m.
FRONT_OVERHANG = 1.2
REAR_OVERHANG = 0.5


@dataclass(frozen=True)
class LoadSettings:
    """``[traffic.loads]`` lowered: the site's model, the seed, the vType mapping and the wander.

    Attributes:
        model: the site's Grave model; site: its name (the ``source`` of the loads it gives).
        seed: the draws' seed (>= 0).
        vtype_classes: vType id -> truck classes (axle counts), ``"car"`` or ``"fixed"``.
        wander: ``"en1991-2"``, ``"none"`` or the standard deviation of a normal wander, m.
    """

    model: GraveModel
    site: str
    seed: int
    vtype_classes: Mapping[str, tuple[int, ...] | str]
    wander: str | float = "en1991-2"

    def wander_of(self, vehicle_id: str) -> float:
        """The vehicle's lateral offset within its lane, m."""
        return lane_wander(self.seed, vehicle_id, self.wander)


@dataclass(frozen=True)
class VehicleDraw:
    """What one vehicle carries.

    Attributes:
        vehicle_type: its own vehicle type (axles, models), or None to keep its vType's.
        vehicle_class: ``truck-N``, ``car``, or its vClass (kept).
        wander: its lateral offset within its lane, m.
        source: where its loads came from.
    """

    vehicle_type: VehicleType | None
    vehicle_class: str
    wander: float
    source: str


def classes_for(model: GraveModel, length: float, front: float, wanted: tuple[int, ...]) -> tuple[int, ...]:
    """The classes of ``wanted`` whose mean wheelbase fits a vehicle of ``length`` m with its front axle
    ``front`` m behind the bumper (and :data:`REAR_OVERHANG` behind the last); the shortest if none fits."""
    room = length - front - REAR_OVERHANG
    wheelbase = {c: sum(s.moments()[0] for s in model.spacings[c - 2]) for c in wanted}
    fit = tuple(c for c in wanted if wheelbase[c] <= room)
    return fit or (min(wanted, key=lambda c: wheelbase[c]),)


class VehicleLoads:
    """Draws each vehicle's loads (the module's docstring); remembers nothing but the vTypes' class choices."""

    def __init__(self, settings: LoadSettings) -> None:
        self.settings = settings
        self._classes: dict[str, tuple[int, ...] | str] = {}

    def plan(self, vtype: VehicleType) -> tuple[int, ...] | str:
        """The vType's choice: truck classes, "car" or "fixed" (worked out once per vType)."""
        plan = self._classes.get(vtype.id)
        if plan is None:
            mapped = self.settings.vtype_classes.get(vtype.id)
            own_weights = vtype.sources.get("mass", "").startswith(("SUMO mass", "vType params")) or \
                vtype.sources.get("axles", "") == "vType params"
            if mapped is not None:
                plan = mapped
            elif own_weights:
                plan = "fixed"  # a vType with its own weights keeps them unless vtype_classes maps it
            elif vtype.vclass in HEAVY_CLASSES:
                plan = HEAVY_CLASSES[vtype.vclass]
            elif vtype.vclass in LIGHT_VCLASSES:
                plan = "car"
            else:
                plan = "fixed"
            if isinstance(plan, tuple):
                plan = classes_for(self.settings.model, vtype.length, _front(vtype), plan)
            self._classes[vtype.id] = plan
        return plan

    def draw(self, vehicle_id: str, vtype: VehicleType, direction: int) -> VehicleDraw:
        """What vehicle ``vehicle_id`` of ``vtype`` carries, driving in Grave's ``direction`` (1: along the
        bridge axis, 2: against it)."""
        s = self.settings
        plan = self.plan(vtype)
        offset = s.wander_of(vehicle_id)
        if plan == "fixed":
            return VehicleDraw(None, vtype.vclass, offset, f"vType {vtype.id}: {vtype.sources.get('mass', '')}")
        if plan == "car":
            load = draw_car(s.seed, vehicle_id)
            label, source = "car", f"{s.site} (light vehicles)"
        else:
            assert isinstance(plan, tuple)
            load = s.model.draw(s.seed, vehicle_id, direction, _restricted_class(s, vehicle_id, direction, plan))
            label, source = f"truck-{load.truck_class}", s.site
        key = f"{vtype.id}@{vehicle_id}"
        fitted, scaled = _fit(load, vtype)
        return VehicleDraw(loaded_vehicle_type(vtype, key, fitted, _front(vtype), source), label, offset,
                           source + ("; spacings scaled to the vType's length" if scaled else ""))


def _front(vtype: VehicleType) -> float:
    """Where the vType's front axle is behind the bumper, m (one contact at mid-length: FRONT_OVERHANG)."""
    if len(vtype.axles) > 1:
        return float(vtype.axles[0][0])
    return min(FRONT_OVERHANG, 0.25 * vtype.length)


def _fit(load: VehicleLoad, vtype: VehicleType) -> tuple[VehicleLoad, bool]:
    """The load with its spacings shortened (in proportion) to fit the vType's length, and whether they were."""
    room = vtype.length - _front(vtype) - REAR_OVERHANG
    wheelbase = sum(load.axle_spacings)
    if wheelbase <= room or wheelbase <= 0.0:
        return load, False
    factor = max(room, 0.1 * vtype.length) / wheelbase
    return replace(load, axle_spacings=tuple(s * factor for s in load.axle_spacings)), True


def _restricted_class(s: LoadSettings, vehicle_id: str, direction: int, allowed: tuple[int, ...]) -> int:
    """A class from the direction's class mix restricted to ``allowed`` (renormalised), from the vehicle's own
    uniform ("class" stream: the load's draw is independent of it)."""
    if len(allowed) == 1:
        return allowed[0]
    weights = [s.model.class_mix[direction - 1][CLASSES.index(c)] for c in allowed]
    total = sum(weights)
    if total <= 0.0:
        weights, total = [1.0] * len(allowed), float(len(allowed))
    u = uniforms(s.seed, vehicle_id, "class", 1)[0] * total
    for c, w in zip(allowed, weights):
        if u < w:
            return c
        u -= w
    return allowed[-1]
