"""The four WIM record formats BTLS reads and writes: their fixed-width columns and raw units (docs/loads.md).

Each record is one line of fixed-width integer fields, right-aligned (BTLS
manual, Appendix 1 "Traffic File Formats"; ``Vehicle.cpp``,
``create*Vehicle`` and ``write*Data``). A header of vehicle fields is followed
by the axles: weight [track width] spacing for each axle, the spacing being to
the next axle. CASTOR, BeDIT and DITIS pad the unused axles with zeros up to
their maximum (9, 20, 20) and give no spacing after the last slot; MON gives
exactly the record's axles, each with a spacing, the last one after the last
axle ("allowing calculation, from the vehicle length, of the front and rear
overhangs").
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

#: Raw units to SI. Weights: BTLS's 1 x 100 kg = 0.981 kN (``KG100_TO_KN``), 1 kg = 9.81e-3 kN.
HUNDRED_KG = 981.0  # N
KG = 9.81  # N
DM, CM, MM = 0.1, 0.01, 0.001  # m
DM_PER_S = 0.1  # m/s
KM_PER_H = 1.0 / 3.6  # m/s


@dataclass(frozen=True)
class Format:
    """One record format.

    Attributes:
        name: the format's name (``castor``, ``bedit``, ``ditis``, ``mon``).
        btls_code: its number in BTLS and pybtls (1-4).
        header: (field, width) of the fields before the axles, in order.
        axle: (field, width) of each axle's fields, in order ("weight", "track", "spacing").
        max_axles: the most axles a record may have.
        padded: whether every line holds ``max_axles`` axle slots (else exactly the record's axles).
        spacing_after_last: whether the last axle has a spacing field (MON's).
        year_digits: 2 or 4.
        direction_base: the direction field's value for direction 1 (1, or 0 when zero-based).
        time_unit: the unit of the sub-minute time, s (0.01: seconds and hundredths fields; 0.001: ms).
        speed, weight, length, transverse, spacing, track: the SI value of one raw unit (m/s, N, m).
    """

    name: str
    btls_code: int
    header: tuple[tuple[str, int], ...]
    axle: tuple[tuple[str, int], ...]
    max_axles: int
    padded: bool
    spacing_after_last: bool
    year_digits: int
    direction_base: int
    time_unit: float
    speed: float
    weight: float
    length: float
    transverse: float
    spacing: float
    track: float

    @cached_property
    def header_width(self) -> int:
        return sum(width for _, width in self.header)

    @cached_property
    def axle_width(self) -> int:
        return sum(width for _, width in self.axle)

    @cached_property
    def header_slices(self) -> tuple[tuple[str, int, int], ...]:
        """(field, start, end) of each header field."""
        return tuple((field, start, end) for field, (start, end) in self.columns().items())

    @cached_property
    def axle_offsets(self) -> dict[str, tuple[int, int]]:
        """Each axle field's (start, end) within an axle's group of columns."""
        out, at = {}, 0
        for field, width in self.axle:
            out[field] = (at, at + width)
            at += width
        return out

    def line_width(self, axles: int) -> int:
        """Characters of a record with ``axles`` axles."""
        spacing = dict(self.axle)["spacing"]
        slots = self.max_axles if self.padded else axles
        width = self.header_width + slots * self.axle_width
        return width if self.spacing_after_last else width - spacing

    def columns(self) -> dict[str, tuple[int, int]]:
        """Each header field's (start, end) character index (0-based, end excluded)."""
        out, at = {}, 0
        for field, width in self.header:
            out[field] = (at, at + width)
            at += width
        return out


_TIME_2 = (("head", 4), ("day", 2), ("month", 2), ("year", 2), ("hour", 2), ("minute", 2), ("second", 2),
           ("hundredths", 2), ("speed", 3), ("gvw", 4), ("length", 3))

CASTOR = Format("castor", 1, _TIME_2 + (("axles", 1), ("direction", 1), ("lane", 1), ("transverse", 3)),
                (("weight", 3), ("spacing", 2)), 9, True, False, 2, 1, 0.01,
                DM_PER_S, HUNDRED_KG, DM, DM, DM, CM)
BEDIT = Format("bedit", 2, _TIME_2 + (("axles", 2), ("direction", 1), ("lane", 1), ("transverse", 3)),
               (("weight", 3), ("spacing", 3)), 20, True, False, 2, 0, 0.01,
               DM_PER_S, HUNDRED_KG, DM, DM, DM, CM)
DITIS = Format("ditis", 3, (("head", 4), ("day", 2), ("month", 2), ("year", 4), ("hour", 2), ("minute", 2),
                            ("second", 2), ("hundredths", 2), ("speed", 3), ("gvw", 4), ("length", 3), ("axles", 2),
                            ("direction", 1), ("lane", 1), ("transverse", 3)),
               (("weight", 3), ("track", 3), ("spacing", 3)), 20, True, False, 4, 1, 0.01,
               DM_PER_S, HUNDRED_KG, DM, CM, DM, CM)
MON = Format("mon", 4, (("head", 9), ("day", 2), ("month", 2), ("year", 4), ("hour", 2), ("minute", 2),
                        ("millis", 5), ("axles", 2), ("groups", 2), ("gvw", 6), ("speed", 3), ("length", 5),
                        ("lane", 1), ("direction", 1), ("transverse", 4)),
             (("weight", 5), ("spacing", 5)), 99, False, True, 4, 0, 0.001,
             KM_PER_H, KG, MM, MM, MM, CM)

FORMATS = {f.name: f for f in (CASTOR, BEDIT, DITIS, MON)}


def format_named(name: str) -> Format:
    """The format called ``name`` (any case).

    Raises:
        KeyError: not one of castor, bedit, ditis, mon (the caller names the key in its error).
    """
    return FORMATS[name.lower()]
