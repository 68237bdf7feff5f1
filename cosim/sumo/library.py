"""cosim's vehicle library: a gross mass, axles and a suspension for every SUMO vehicle class.

Used for a vType that sets neither SUMO's ``mass`` nor ``cosim.*`` params
(and, for what it does not set, for one that sets some): SUMO's default masses
(a 4.5 t ``truck``, a 10 kg ``bicycle``) are never used. Each number names
its source; where no published set exists, the value is cosim's own choice
and says so. Data only: :mod:`cosim.sumo.vtypes` turns an entry into vehicle
models.

Sources:

- **EN 1991-2:2003, Table 4.7**, fatigue load model 4 (FLM4), the "set of
  equivalent lorries": lorry 1 (2 axles, 4.5 m apart, 70 + 130 kN), lorry 2
  (3 axles, 4.2 and 1.3 m, 70 + 120 + 120 kN) and lorry 3 (articulated, 5 axles,
  3.2, 5.2, 1.3 and 1.3 m, 70 + 150 + 90 + 90 + 90 kN). The loads are the code's
  equivalent axle loads of European lorry traffic, used here as gross weights
  (mass = load / 9.81 m/s^2).
- **IRI "golden car"** (Sayers, Gillespie & Queiroz, *The International Road
  Roughness Experiment*, World Bank Technical Paper 45, 1986; ASTM E1926): a
  quarter-car with k_s/m_s = 63.3 1/s^2, c_s/m_s = 6.0 1/s, k_t/m_s = 653 1/s^2,
  m_u/m_s = 0.15, for cars, vans and two-wheelers.
- **Council Directive 96/53/EC, Annex III**: a suspension is "road friendly"
  (equivalent to air suspension) with a sprung-mass bounce frequency of at most
  2.0 Hz and a damping of at least 20 % of critical; trucks and buses here sit
  at those limits (2.0 Hz, 20 %), with an axle hop of 10 Hz and an unsprung
  mass of 10 % of the axle's load (cosim's choice, typical of heavy axles).
- **Regulation (EU) 2018/858, Art. 4**: category N1 (light goods vehicles) ends
  at 3.5 t gross: the van.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

__all__ = ["ENTRIES", "FALLBACK", "GOLDEN_CAR", "HEAVY_VCLASSES", "ROAD_FRIENDLY", "LibraryVehicle", "Suspension",
           "entry_for"]

#: SUMO vehicle classes that count as trucks (a study's ``truck_share``).
HEAVY_VCLASSES = ("bus", "coach", "truck", "trailer")

G_FLM4 = 9.81  # m/s^2: FLM4 axle loads (kN) to masses


@dataclass(frozen=True)
class Suspension:
    """A quarter-car parameter set per unit sprung (body) mass, so that it scales to any mass.

    Attributes:
        name: how summaries name it; source: where the numbers come from.
        k_v, c_v, k_t, c_t: suspension and tyre stiffness (1/s^2) and damping (1/s) per kg of body.
        m_w: unsprung (wheel and axle) mass per kg of body.
    """

    name: str
    source: str
    k_v: float
    c_v: float
    k_t: float
    c_t: float
    m_w: float

    @classmethod
    def from_frequencies(cls, name: str, source: str, body_hz: float, damping: float, hop_hz: float,
                         unsprung: float) -> Suspension:
        """A set with body bounce ``body_hz`` (on a rigid tyre: sqrt(k_v / m_v) / 2 pi), suspension damping
        ratio ``damping``, axle hop ``hop_hz`` (sqrt((k_v + k_t) / m_w) / 2 pi) and an unsprung share
        ``unsprung`` of the gross mass."""
        m_w = unsprung / (1.0 - unsprung)
        k_v = (2 * math.pi * body_hz) ** 2
        c_v = 2 * damping * 2 * math.pi * body_hz
        k_t = m_w * (2 * math.pi * hop_hz) ** 2 - k_v
        return cls(name, source, k_v, c_v, k_t, 0.0, m_w)

    def unsprung_share(self) -> float:
        """The unsprung mass as a share of the gross mass."""
        return self.m_w / (1.0 + self.m_w)


GOLDEN_CAR = Suspension(
    "IRI golden car", "Sayers, Gillespie & Queiroz 1986, World Bank TP 45 (ASTM E1926)",
    k_v=63.3, c_v=6.0, k_t=653.0, c_t=0.0, m_w=0.15)
ROAD_FRIENDLY = Suspension.from_frequencies(
    "road-friendly heavy axle", "Directive 96/53/EC Annex III (2.0 Hz, 20 %); axle hop 10 Hz, 10 % unsprung "
    "(cosim's choice)", body_hz=2.0, damping=0.20, hop_hz=10.0, unsprung=0.10)


@dataclass(frozen=True)
class LibraryVehicle:
    """One vehicle of the library.

    Attributes:
        name: e.g. "EN 1991-2 FLM4 lorry 3".
        mass: gross mass, kg; mass_source: where it comes from.
        axles: distances of the axles behind the front bumper, m, for a vehicle ``length`` m long;
        loads: each axle's share of the weight (sum 1); axles_source: where they come from.
        suspension: the quarter-car set every axle carries (scaled by its share).
        length: the vehicle length the axle positions are given for, m.
    """

    name: str
    mass: float
    mass_source: str
    axles: tuple[float, ...]
    loads: tuple[float, ...]
    axles_source: str
    suspension: Suspension
    length: float

    def axles_for(self, length: float) -> tuple[tuple[float, ...], bool]:
        """Axle positions on a vehicle ``length`` m long: as given, or scaled down to fit a shorter vehicle
        (then True)."""
        if length >= self.length:
            return self.axles, False
        factor = length / self.length
        return tuple(d * factor for d in self.axles), True


def _flm4(lorry: int, spacings: tuple[float, ...], loads_kn: tuple[float, ...], front: float,
          length: float) -> LibraryVehicle:
    where = [front]
    for s in spacings:
        where.append(where[-1] + s)
    total = sum(loads_kn)
    return LibraryVehicle(
        name=f"EN 1991-2 FLM4 lorry {lorry}",
        mass=total * 1e3 / G_FLM4,
        mass_source=f"EN 1991-2 Table 4.7, lorry {lorry}: {' + '.join(f'{v:g}' for v in loads_kn)} kN",
        axles=tuple(where),
        loads=tuple(v / total for v in loads_kn),
        axles_source=f"EN 1991-2 Table 4.7, lorry {lorry}: spacings {', '.join(f'{s:g}' for s in spacings)} m "
                     f"(front overhang {front:g} m: cosim's choice)",
        suspension=ROAD_FRIENDLY, length=length)


def _light(name: str, mass: float, mass_source: str, front: float, wheelbase: float, loads: tuple[float, float],
           length: float) -> LibraryVehicle:
    return LibraryVehicle(
        name=name, mass=mass, mass_source=mass_source, axles=(front, front + wheelbase), loads=loads,
        axles_source=f"wheelbase {wheelbase:g} m, front overhang {front:g} m, loads "
                     f"{loads[0]:g}/{loads[1]:g} (cosim's choice)",
        suspension=GOLDEN_CAR, length=length)


CAR = _light("car", 1500.0, "a mid-size car with its driver (cosim's choice)", 0.9, 2.7, (0.55, 0.45), 5.0)
VAN = _light("van", 3500.0, "the N1 limit, Regulation (EU) 2018/858", 1.0, 3.5, (0.45, 0.55), 6.5)
MOTORCYCLE = _light("motorcycle", 250.0, "motorcycle and rider (cosim's choice)", 0.35, 1.5, (0.45, 0.55), 2.2)
MOPED = _light("moped", 150.0, "moped and rider (cosim's choice)", 0.3, 1.3, (0.45, 0.55), 2.1)
BICYCLE = _light("bicycle", 90.0, "bicycle and rider (cosim's choice)", 0.25, 1.1, (0.4, 0.6), 1.6)
LORRY_1 = _flm4(1, (4.5,), (70.0, 130.0), 1.3, 7.1)
BUS = replace(_flm4(1, (4.5,), (70.0, 130.0), 2.6, 12.0), name="bus (EN 1991-2 FLM4 lorry 1)")
COACH = replace(_flm4(2, (4.2, 1.3), (70.0, 120.0, 120.0), 2.6, 14.0), name="coach (EN 1991-2 FLM4 lorry 2)")
LORRY_3 = _flm4(3, (3.2, 5.2, 1.3, 1.3), (70.0, 150.0, 90.0, 90.0, 90.0), 1.4, 16.5)

#: SUMO vClass -> library vehicle.
ENTRIES: dict[str, LibraryVehicle] = {
    **dict.fromkeys(("passenger", "private", "taxi", "evehicle", "hov", "vip", "army", "authority", "custom1",
                     "custom2", "ignoring"), CAR),
    **dict.fromkeys(("delivery", "emergency"), VAN),
    "truck": LORRY_1,
    "trailer": LORRY_3,
    "bus": BUS,
    "coach": COACH,
    "motorcycle": MOTORCYCLE,
    "moped": MOPED,
    **dict.fromkeys(("bicycle", "scooter"), BICYCLE),
}
#: The entry of a vClass without one (rail, tram, ship, ...): named as such wherever it is used.
FALLBACK = CAR


def entry_for(vclass: str) -> tuple[LibraryVehicle, str]:
    """The library vehicle of ``vclass`` and a note ("" or why it is a stand-in)."""
    entry = ENTRIES.get(vclass)
    if entry is not None:
        return entry, ""
    return FALLBACK, f"vClass {vclass!r} has no vehicle of its own in cosim's library: the {FALLBACK.name} stands in"
