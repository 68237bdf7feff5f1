"""Section constants shared by the verification tests (explicit, so each closed form sees exactly them).

The one copy lives in :mod:`cosim.validation.references` (``cosim validate`` uses the same beams).
"""
from __future__ import annotations

from cosim.validation.references import STEEL
from cosim.validation.references import doubly_symmetric_section as doubly_symmetric
from cosim.validation.references import monosymmetric_section as monosymmetric
from cosim.validation.references import rectangle_section as rectangle

__all__ = ["STEEL", "doubly_symmetric", "monosymmetric", "rectangle"]
