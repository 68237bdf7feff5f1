"""Messages of a fixed shape, rendered by filling their numbers into an encoded template in one compiled pass.

The 3D scene (:mod:`cosim.log.scene`) writes the same entities at every
scene with only their numbers changed: the deck's drawn heights and the
timestamps. Formatting those as one Python object per number cost a tenth to
a fifth of the log writer's CPU; a :class:`FilledTemplate` writes the numbers of
many messages straight into one byte buffer (the writer's CPU for the same
messages of a 10-minute default run: 1.13-1.65 s before, 1.06-1.31 s after).

Numbers are written as orjson writes them (the JSON of the rest of the log):
a centimetre value as ``round(x, 2)`` in its shortest form (``2.0``,
``-0.05``, ``123.4``), an integer as its digits, a value that is not finite
as ``null``.
"""
from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np

from cosim.core.jit import compiled

__all__ = ["CENTIMETRE", "INTEGER", "LARGEST_DRAWN", "FilledTemplate", "holes"]

#: Kinds of holes: a number rounded to the centimetre (numpy's ``round(x, 2)``), an integer.
CENTIMETRE = 0
INTEGER = 1
#: Drawn numbers are clipped to this magnitude, m, where a hundredth is still exact in a float (no picture of
#: a bridge comes near it; orjson would write the unclipped value).
LARGEST_DRAWN = 1e12
_HOLE = re.compile(rb"%%|%s")
_NUMBER_BYTES = 24  # the longest number written: "-" and 16 digits, ".", two digits; or a 19-digit integer


@compiled
def _write_int(out: np.ndarray, at: int, value: int) -> int:
    """The decimal digits of ``value`` (>= 0) at ``out[at:]``; returns the end."""
    digits = 1
    rest = value // 10
    while rest:
        digits += 1
        rest //= 10
    end = at + digits
    for k in range(end - 1, at - 1, -1):
        out[k] = 48 + value % 10
        value //= 10
    return end


@compiled
def _fill(pieces: np.ndarray, piece_ends: np.ndarray, kinds: np.ndarray, values: np.ndarray,
          out: np.ndarray, ends: np.ndarray) -> None:
    """Message i = piece 0, hole 0 of row i, piece 1, ..., last piece; written one after another into ``out``.

    Hand-written because no library formats numbers into a byte template without a Python object per number.
    """
    at = 0
    holes = values.shape[1]
    for i in range(values.shape[0]):
        start = 0
        for h in range(holes + 1):
            stop = piece_ends[h]
            for k in range(start, stop):
                out[at] = pieces[k]
                at += 1
            start = stop
            if h == holes:
                break
            x = values[i, h]
            if not np.isfinite(x):
                out[at], out[at + 1], out[at + 2], out[at + 3] = 110, 117, 108, 108  # "null", as orjson
                at += 4
                continue
            if kinds[h] == INTEGER:
                n = np.int64(x)
                if n < 0:
                    out[at] = 45  # "-"
                    at += 1
                    n = -n
                at = _write_int(out, at, n)
                continue
            x = min(max(x, -LARGEST_DRAWN), LARGEST_DRAWN)
            cents = np.int64(np.rint(x * 100.0))  # numpy's round(x, 2): rint(x * 100) / 100
            if cents < 0:
                out[at] = 45
                at += 1
                cents = -cents
            at = _write_int(out, at, cents // 100)
            out[at] = 46  # "."
            at += 1
            fraction = cents % 100
            if fraction % 10 == 0:  # the shortest form: "2.0", "2.5"
                out[at] = 48 + fraction // 10
                at += 1
            else:
                out[at] = 48 + fraction // 10
                out[at + 1] = 48 + fraction % 10
                at += 2
        ends[i] = at


def holes(template: bytes) -> int:
    """The holes (``%s``) of a bytes %-template."""
    return sum(match == b"%s" for match in _HOLE.findall(template))


class FilledTemplate:
    """An encoded message with holes, rendered for many rows of numbers at once.

    Args:
        template: a bytes %-template: ``%s`` marks a hole, ``%%`` a literal ``%``.
        kinds: per hole, :data:`CENTIMETRE` or :data:`INTEGER`.
    """

    def __init__(self, template: bytes, kinds: Sequence[int]) -> None:
        pieces = []
        current = bytearray()
        position = 0
        for match in _HOLE.finditer(template):
            current += template[position:match.start()]
            if match.group() == b"%%":
                current += b"%"
            else:
                pieces.append(bytes(current))
                current = bytearray()
            position = match.end()
        current += template[position:]
        pieces.append(bytes(current))
        if len(kinds) != len(pieces) - 1:
            raise ValueError(f"FilledTemplate: {len(pieces) - 1} holes, {len(kinds)} kinds")
        self.holes = len(pieces) - 1
        self._pieces = np.frombuffer(b"".join(pieces), dtype=np.uint8)
        self._piece_ends = np.cumsum([len(p) for p in pieces]).astype(np.int64)
        self._kinds = np.asarray(kinds, dtype=np.int64)

    def render(self, values: np.ndarray) -> list[bytes]:
        """One message per row of ``values`` (rows, holes)."""
        values = np.ascontiguousarray(values, dtype=np.float64)
        if values.ndim != 2 or values.shape[1] != self.holes:
            raise ValueError(f"FilledTemplate.render: expected (rows, {self.holes}) numbers, got {values.shape}")
        rows = values.shape[0]
        out = np.empty(rows * (len(self._pieces) + self.holes * _NUMBER_BYTES), dtype=np.uint8)
        ends = np.zeros(rows, dtype=np.int64)
        _fill(self._pieces, self._piece_ends, self._kinds, values, out, ends)
        data = out.tobytes()
        starts = [0, *ends[:-1].tolist()]
        return [data[a:b] for a, b in zip(starts, ends.tolist())]
