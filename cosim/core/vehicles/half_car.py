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

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from cosim.errors import ConfigError

from .base import LINEAR, check_non_negative, check_positive

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
class HalfCar:
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
    def kernel_kind(self) -> int:
        """Compiled kind: a linear vehicle."""
        return LINEAR

    @property
    def contacts(self) -> int:
        """Contact points (axles)."""
        return len(self.axles)

    @property
    def contact_offsets(self) -> tuple[float, ...]:
        """Each axle's distance behind the vehicle's contact point (its front axle), m."""
        return tuple(a.distance for a in self.axles)

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
        loads = static_axle_loads(mv, kv, b, k_t, gravity)
        return {"mv": mv, "cv": cv, "kv": kv, "b": b, "k_t": k_t, "c_t": c_t, "loads": loads, "obs": obs}


def static_axle_loads(mv: np.ndarray, kv: np.ndarray, b: np.ndarray, k_t: np.ndarray, gravity: float) -> np.ndarray:
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


def tyre_quarter_car_system(m_v: float, m_w: float, k_v: float, c_v: float, k_t: float, c_t: float,
                            gravity: float) -> dict[str, np.ndarray]:
    """The tyre quarter-car as a linear vehicle [body, wheel] (for unilateral contact)."""
    mv = np.diag([m_v, m_w])
    kv = k_v * np.array([[1.0, -1.0], [-1.0, 1.0]])
    cv = c_v * np.array([[1.0, -1.0], [-1.0, 1.0]])
    b = np.array([[0.0, 1.0]])
    obs = np.array([[1.0, 0.0]])
    return {"mv": mv, "cv": cv, "kv": kv, "b": b, "k_t": np.array([k_t]), "c_t": np.array([c_t]),
            "loads": np.array([(m_v + m_w) * gravity]), "obs": obs}
