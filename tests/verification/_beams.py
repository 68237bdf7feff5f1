"""Section constants shared by the verification tests (explicit, so each closed form sees exactly them).

The one copy lives in :mod:`cosim.references` (``cosim validate`` uses the same beams).
"""
from __future__ import annotations

from cosim.references import STEEL
from cosim.references import doubly_symmetric_section as doubly_symmetric
from cosim.references import monosymmetric_section as monosymmetric
from cosim.references import rectangle_section as rectangle

__all__ = ["STEEL", "doubly_symmetric", "monosymmetric", "rectangle"]
