"""The half-car: a body that bounces and pitches on any number of axles (docs/theory.md §11.1).

The pitch-plane vehicle model of the vehicle-bridge literature, with as many
axles as the vehicle has: body mass ``m_b`` and pitch inertia ``i_b`` about
its centre of gravity, and per axle a wheel ``m_w`` on a suspension ``k_s,
c_s`` under the body and a tyre ``k_t, c_t`` on the road. Two axles make the
classical half-car; three or more make a truck whose tandem or tridem shares
the body's load through the body's stiffness (statically indeterminate: the
axle loads follow from the springs). With ``pitch = False`` the body only
bounces: a rigid load-sharing group whose axles are tied together.

Positions are distances behind the front axle (m): the first axle is at 0,
the centre of gravity at ``cg``. The vehicle's contact point in a traffic
source is its front axle; the others follow behind it.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from cosim.errors import ConfigError

from .base import LINEAR, ContactPoint, VehicleModel, check_non_negative, check_positive
from .registry import ModelSpec, Parameter, VTypeInputs, VTypeRecipe
from .tyre_quarter_car import VTYPE_PARAMETERS, from_vtype

#: Largest number of axles of one vehicle (bounds the compiled per-vehicle work).
MAX_AXLES = 12


@dataclass(frozen=True)
class Axle:
    """One axle of a :class:`HalfCar` (both wheels of the axle together).

    Args:
        distance: behind the front axle, m (the front axle is at 0).
        m_w: wheel (unsprung) mass, kg.
        k_s, c_s: suspension, N/m and N s/m.
        k_t, c_t: tyre, N/m and N s/m.
    """

    distance: float
    m_w: float
    k_s: float
    c_s: float
    k_t: float
    c_t: float = 0.0

    def check(self, owner: str) -> None:
        """Raise ConfigError naming ``owner`` for a non-physical parameter."""
        check_non_negative(owner, distance=self.distance, c_s=self.c_s, c_t=self.c_t)
        check_positive(owner, m_w=self.m_w, k_s=self.k_s, k_t=self.k_t)


@dataclass(frozen=True)
class HalfCar(VehicleModel):
    """A body with bounce (and pitch) on several axles, each with its own suspension, wheel and tyre.

    Args:
        m_b: body (sprung) mass, kg.
        i_b: body pitch inertia about its centre of gravity, kg m^2 (> 0 with pitch).
        cg: centre of gravity behind the front axle, m.
        axles: the axles, front first (distances increasing).
        pitch: the body pitches (True) or only bounces (False).
        unilateral: tyres may leave the deck (True) or always hold to it (False).
    """

    m_b: float
    i_b: float
    cg: float
    axles: tuple[Axle, ...]
    pitch: bool = True
    unilateral: bool = False
    kind: ClassVar[str] = "half-car"
    KIND: ClassVar[int] = LINEAR

    def __post_init__(self) -> None:
        owner = "half-car"
        check_positive(owner, m_b=self.m_b)
        check_non_negative(owner, i_b=self.i_b, cg=self.cg)
        if not isinstance(self.axles, tuple) or not self.axles or \
                not all(isinstance(a, Axle) for a in self.axles):
            raise ConfigError(f"{owner}: `axles` must be a non-empty tuple of Axle (got {self.axles!r})")
        if len(self.axles) > MAX_AXLES:
            raise ConfigError(f"{owner}: at most {MAX_AXLES} axles (got {len(self.axles)})")
        for i, axle in enumerate(self.axles):
            axle.check(f"{owner} axle {i + 1}")
        distances = [a.distance for a in self.axles]
        if distances[0] != 0.0 or any(b <= a for a, b in zip(distances, distances[1:])):
            raise ConfigError(f"{owner}: axle distances must start at 0 (the front axle) and increase "
                              f"(got {distances})")
        if not isinstance(self.pitch, bool) or not isinstance(self.unilateral, bool):
            raise ConfigError(f"{owner}: `pitch` and `unilateral` must be true or false")
        if self.pitch and not self.i_b > 0:
            raise ConfigError(f"{owner}: `i_b` must be > 0 kg m^2 for a pitching body (or set pitch = false)")
        if self.pitch and len(self.axles) == 1:
            raise ConfigError(f"{owner}: one axle cannot carry a pitching body; set pitch = false")

    @property
    def total_mass(self) -> float:
        """kg."""
        return float(self.m_b + sum(a.m_w for a in self.axles))

    @property
    def contact_points(self) -> tuple[ContactPoint, ...]:
        """One per axle, on the path: its distance behind the front axle, m."""
        return tuple(ContactPoint(a.distance, 0.0) for a in self.axles)

    def pack(self) -> tuple[float, ...]:
        """Compiled parameters of a contact column: none beyond the per-axle ones of :meth:`linear_system`."""
        return ()

    def record(self) -> dict[str, float]:
        """The model as numbers only (for logs): axle k's parameters under ``axle<k>.<name>``."""
        out: dict[str, float] = {"m_b": self.m_b, "i_b": self.i_b, "cg": self.cg, "pitch": float(self.pitch),
                                 "unilateral": float(self.unilateral)}
        for k, axle in enumerate(self.axles, start=1):
            for name in ("distance", "m_w", "k_s", "c_s", "k_t", "c_t"):
                out[f"axle{k}.{name}"] = getattr(axle, name)
        return out

    @classmethod
    def from_record(cls, values: dict[str, Any]) -> HalfCar:
        """The inverse of :meth:`record` (values already checked to be numbers)."""
        count = 0
        while f"axle{count + 1}.distance" in values:
            count += 1
        try:
            axles = tuple(Axle(**{name: values[f"axle{k}.{name}"] for name in
                                  ("distance", "m_w", "k_s", "c_s", "k_t", "c_t")}) for k in range(1, count + 1))
            return cls(m_b=values["m_b"], i_b=values["i_b"], cg=values["cg"], axles=axles,
                       pitch=bool(values.get("pitch", 1.0)), unilateral=bool(values.get("unilateral", 0.0)))
        except KeyError as exc:
            raise ConfigError(f"half-car: missing parameter {exc.args[0]!r}") from None

    def linear_system(self, gravity: float) -> dict[str, np.ndarray]:
        """Matrices of the vehicle's DOFs [bounce, (pitch,) wheels] (docs/theory.md §11.1).

        Returns ``mv, cv, kv`` (nz, nz), ``b`` (contacts, nz: the wheel under each
        tyre), ``k_t, c_t`` (contacts,), ``loads`` (the static axle loads on a rigid,
        level road, N) and ``obs`` (contacts, nz: the body's vertical motion above each axle).
        """
        n = len(self.axles)
        nb = 2 if self.pitch else 1
        nz = nb + n
        mv = np.zeros((nz, nz))
        cv = np.zeros((nz, nz))
        kv = np.zeros((nz, nz))
        b = np.zeros((n, nz))
        obs = np.zeros((n, nz))
        mv[0, 0] = self.m_b
        if self.pitch:
            mv[1, 1] = self.i_b
        for k, axle in enumerate(self.axles):
            lever = self.cg - axle.distance  # > 0: the axle is ahead of the centre of gravity (nose-up pitch lifts it)
            body = np.zeros(nz)
            body[0] = 1.0
            if self.pitch:
                body[1] = lever
            stretch = body.copy()
            stretch[nb + k] = -1.0  # suspension stretch: body above the axle minus wheel
            kv += axle.k_s * np.outer(stretch, stretch)
            cv += axle.c_s * np.outer(stretch, stretch)
            mv[nb + k, nb + k] = axle.m_w
            b[k, nb + k] = 1.0
            obs[k] = body
        k_t = np.array([a.k_t for a in self.axles])
        c_t = np.array([a.c_t for a in self.axles])
        loads = linear_axle_loads(mv, kv, b, k_t, gravity)
        return {"mv": mv, "cv": cv, "kv": kv, "b": b, "k_t": k_t, "c_t": c_t, "loads": loads, "obs": obs}


def linear_axle_loads(mv: np.ndarray, kv: np.ndarray, b: np.ndarray, k_t: np.ndarray, gravity: float) -> np.ndarray:
    """The tyre loads (N, compression positive) of a linear vehicle at rest on a rigid, level road.

    Gravity acts on every translational mass (the diagonal of ``mv`` on DOFs that
    move vertically; a pitch DOF about the centre of gravity gets no moment).
    """
    k_total = kv + (b.T * k_t) @ b
    vertical = np.array([1.0 if _is_translation(mv, b, i) else 0.0 for i in range(len(mv))])
    weights = -gravity * np.diag(mv) * vertical
    z_static = np.linalg.solve(k_total, weights)
    return -k_t * (b @ z_static)


def _is_translation(mv: np.ndarray, b: np.ndarray, i: int) -> bool:
    # DOF 0 is the bounce, wheels are the DOFs under a tyre; a pitch DOF (1, when present) is not a translation.
    return i == 0 or bool(np.any(b[:, i] != 0.0))


AXLE_FIELDS = (
    Parameter("distance", "m", "behind the front axle: the first is `0`, then increasing", at_least=0.0),
    Parameter("m_w", "kg", "the axle's wheels", above=0.0),
    Parameter("k_s", "N/m", "the axle's suspension stiffness", above=0.0),
    Parameter("c_s", "N s/m", "the axle's suspension damping", at_least=0.0),
    Parameter("k_t", "N/m", "the axle's tyres", above=0.0),
    Parameter("c_t", "N s/m", "the axle's tyre damping", 0.0, at_least=0.0),
)


def _from_table(values: Mapping[str, Any], unilateral: bool) -> HalfCar:
    return HalfCar(m_b=values["m_b"], i_b=values["i_b"], cg=values["cg"],
                   axles=tuple(Axle(**axle) for axle in values["axles"]), pitch=values["pitch"],
                   unilateral=unilateral)


def _from_vtype(vtype: VTypeInputs) -> HalfCar:
    """One body on the vType's axles: per axle its share of the whole vehicle's suspension (docs/sumo.md).

    The body's centre of gravity is where the axle loads put it (sum of share x distance, so a two-axle body
    carries exactly the shares); its pitch inertia ``cosim.i_b`` or that of a uniform body as long as the
    vehicle (m_b L^2 / 12); it pitches unless ``cosim.pitch = false`` or it has one axle.
    """
    quarter = from_vtype(vtype)  # the whole vehicle on one tyre, checked as such
    axles = vtype.axles
    front = axles[0][0]
    pitch, i_b = vtype.values["pitch"], vtype.values["i_b"]
    m_b = quarter.m_v
    return HalfCar(
        m_b=m_b, i_b=m_b * vtype.length**2 / 12.0 if i_b is None else i_b,
        cg=sum(share * (d - front) for d, share in axles),  # the axle loads' resultant: the shares hold
        axles=tuple(Axle(distance=d - front, m_w=share * quarter.m_w, k_s=share * quarter.k_v,
                         c_s=share * quarter.c_v, k_t=share * quarter.k_t, c_t=share * quarter.c_t)
                    for d, share in axles),
        pitch=len(axles) > 1 if pitch is None else pitch, unilateral=vtype.unilateral)


SPEC = ModelSpec(
    name=HalfCar.kind, cls=HalfCar,
    doc="a body of mass `m_b` and pitch inertia `i_b` about its centre of gravity, `cg` metres behind the front "
        "axle, on any number of axles, each with its own suspension, wheel and tyre (docs/theory.md §11): the "
        "pitch-plane model of two-axle cars and of trucks with tandem or tridem groups, whose axles share the "
        "body's load through its springs. With `pitch = false` the body only bounces: the axles are tied into "
        "one load-sharing group. One contact point per axle",
    parameters=(
        Parameter("m_b", "kg", "body (sprung) mass", above=0.0),
        Parameter("i_b", "kg m^2", "body pitch inertia about its centre of gravity", 0.0, at_least=0.0,
                  note="> 0 with pitch"),
        Parameter("cg", "m", "centre of gravity behind the front axle", at_least=0.0),
        Parameter("axles", "", "front axle first", kind="tables", fields=AXLE_FIELDS),
        Parameter("pitch", "", "the body pitches (or only bounces)", True, kind="flag"),
    ),
    build=_from_table,
    example=HalfCar(m_b=16000.0, i_b=6e4, cg=2.2, axles=(Axle(0.0, 700.0, 6e5, 3e4, 2.5e6, 2e3),
                                                         Axle(4.0, 1100.0, 9e5, 5e4, 4e6, 3e3))),
    tyre=True,
    vtype=VTypeRecipe(
        parameters=(*VTYPE_PARAMETERS,
                    Parameter("pitch", "", "the body pitches (default: unless it has one axle)", None, kind="flag"),
                    Parameter("i_b", "kg m^2", "body pitch inertia (default: a uniform body as long as the vehicle, "
                              "m_b L^2 / 12)", None)),
        build=_from_vtype, one_body=True),
)
