"""What a validation case returns: frozen values, no drawing and no Markdown.

A study (:mod:`cosim.validation.cases`) computes one or more :class:`CaseResult`
(error, tolerance, the reference's source, the numbers behind the error) and
the data of its figures, together a :class:`StudyResult`. The report writer
(:mod:`cosim.validation.report`) turns them into Markdown and PNGs; the
verification tests assert on the same values.
"""
from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Union

import numpy as np

__all__ = ["CaseResult", "Detail", "FigureData", "StudyResult", "Table", "format_number", "judge"]


def format_number(value: float | None, digits: int = 3) -> str:
    """A number for a table or a summary: fixed between 1e-3 and 1e4, else scientific; ``-`` for None."""
    if value is None:
        return "-"
    if value == 0:
        return "0"
    return f"{value:.{digits}g}" if 1e-3 <= abs(value) < 1e4 else f"{value:.{digits - 1}e}"


def judge(error: float | None, tolerance: float) -> bool:
    """``error <= tolerance`` for a finite ``error``."""
    return error is not None and math.isfinite(error) and error <= tolerance


@dataclass(frozen=True)
class Table:
    """A table of a case's numbers, cells already formatted (the report lays it out); stored as tuples."""

    header: Sequence[str]
    rows: Sequence[Sequence[str]]

    def __post_init__(self) -> None:
        object.__setattr__(self, "header", tuple(self.header))
        object.__setattr__(self, "rows", tuple(tuple(row) for row in self.rows))


#: One block of a case's details: a paragraph of plain text or a table.
Detail = Union[str, Table]


@dataclass(frozen=True)
class CaseResult:
    """One validation case.

    Attributes:
        name: unique, human-readable name (the report's heading).
        reference: what the model is compared with, source named.
        metric: how ``error`` is measured (its unit).
        error: the measured error, or None for an informational case that has none.
        tolerance: the largest acceptable ``error``; None for informational cases.
        passed: the case met its tolerance (informational cases pass unless they crashed);
            by default judged from ``error`` and ``tolerance``.
        figures: file names of this case's figures (drawn from its study's :attr:`StudyResult.figures`).
        details: the numbers behind ``error``, in report order (paragraphs and tables).
        values: the same numbers by name (SI units), for tests and scripts.
        group: the title of the study the case belongs to (the report's section).
    """

    name: str
    reference: str
    metric: str
    error: float | None
    tolerance: float | None
    passed: bool | None = None
    figures: tuple[str, ...] = ()
    details: tuple[Detail, ...] = ()
    values: Mapping[str, float] = field(default_factory=dict)
    group: str = ""

    def __post_init__(self) -> None:
        if self.error is not None:
            object.__setattr__(self, "error", float(self.error))
        if self.tolerance is not None:
            object.__setattr__(self, "tolerance", float(self.tolerance))
        object.__setattr__(self, "figures", tuple(self.figures))
        object.__setattr__(self, "details", tuple(self.details))
        object.__setattr__(self, "values", MappingProxyType({k: float(v) for k, v in self.values.items()}))
        if self.passed is None:  # judged: within tolerance (an informational case passes)
            object.__setattr__(self, "passed", self.tolerance is None or judge(self.error, self.tolerance))

    @property
    def informational(self) -> bool:
        """No tolerance: reported, not judged."""
        return self.tolerance is None

    @property
    def status(self) -> str:
        """``PASS``, ``FAIL`` or ``INFO``."""
        if not self.passed:
            return "FAIL"
        return "INFO" if self.informational else "PASS"


@dataclass(frozen=True)
class FigureData:
    """The data of one figure; subclasses add the arrays. ``file`` is the PNG's name in the output directory.

    Arrays (alone or in tuples) are stored as read-only copies: the data is frozen like the dataclass.
    """

    file: str

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, np.ndarray):
                object.__setattr__(self, f.name, _frozen(value))
            elif isinstance(value, tuple) and any(isinstance(item, np.ndarray) for item in value):
                object.__setattr__(self, f.name, tuple(_frozen(item) for item in value))


def _frozen(value: object) -> object:
    if not isinstance(value, np.ndarray):
        return value
    copy = value.copy()
    copy.flags.writeable = False
    return copy


@dataclass(frozen=True)
class StudyResult:
    """What one study computed: its cases and the data of its figures."""

    cases: tuple[CaseResult, ...]
    figures: tuple[FigureData, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "cases", tuple(self.cases))
        object.__setattr__(self, "figures", tuple(self.figures))

    def case(self, name: str) -> CaseResult:
        """The case called ``name``."""
        for case in self.cases:
            if case.name == name:
                return case
        raise KeyError(f"no case {name!r} (cases: {', '.join(c.name for c in self.cases)})")
