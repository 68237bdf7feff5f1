"""The one list of validation studies: names, report titles, quick and full settings.

``cosim validate`` runs them in this order (``--quick``: the quick settings),
and ``tests/verification`` parametrizes over the same list at the quick
settings, so the report and the tests cannot drift apart. A study is a function
of :mod:`cosim.validation.cases` returning a
:class:`~cosim.validation.results.StudyResult`; its settings are the keyword
arguments it is called with.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

from cosim.errors import CosimError

from . import cases
from .results import StudyResult

__all__ = ["STUDIES", "Study", "select", "study", "study_names"]


@dataclass(frozen=True)
class Study:
    """One registered study.

    Attributes:
        name: short name (``cosim validate`` progress, ``only=``).
        title: the report's section; every case of the study carries it as its ``group``.
        compute: the study (keyword arguments: its settings).
        quick: settings of ``--quick`` runs and of the verification tests.
        full: settings of the full report.
    """

    name: str
    title: str
    compute: Callable[..., StudyResult]
    quick: Mapping[str, Any] = field(default_factory=dict)
    full: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "quick", MappingProxyType(dict(self.quick)))
        object.__setattr__(self, "full", MappingProxyType(dict(self.full)))

    def settings(self, quick: bool) -> Mapping[str, Any]:
        """The keyword arguments of :attr:`compute` for a quick or a full run."""
        return self.quick if quick else self.full

    def run(self, quick: bool) -> StudyResult:
        """Compute the study; its cases carry :attr:`title` as their ``group``."""
        result = self.compute(**self.settings(quick))
        return replace(result, cases=tuple(replace(c, group=self.title) for c in result.cases))


#: Every study, in report order. Quick settings are coarser only where the full ones cost seconds
#: (the Fryba steps; the sprung mass's steps and its reference's modes and rtol; the VBI-2D reference's modes
#: and rtol) and pass the same tolerances.
STUDIES: tuple[Study, ...] = (
    Study("paper", "Paper case: 40 m double-tee (Figs. 4-6)", cases.paper_case,
          quick={"dt": 0.005}, full={"dt": 0.005}),
    Study("timoshenko-static", "Timoshenko static deflection", cases.timoshenko_static),
    Study("timoshenko-frequencies", "Timoshenko frequencies", cases.timoshenko_frequencies),
    Study("torsion-static", "Non-uniform torsion", cases.torsion_static),
    Study("torsional-frequencies", "Torsional frequencies", cases.torsional_frequencies),
    Study("lateral-torsional", "Coupled lateral-torsional frequencies", cases.lateral_torsional_frequencies),
    Study("fryba", "Moving force (Fryba)", cases.fryba_moving_force,
          quick={"steps": 500}, full={"steps": 2000}),
    Study("sprung-mass", "Moving sprung mass", cases.sprung_mass,
          quick={"steps": 1000, "modes": 10, "rtol": 1e-8}, full={"steps": 4000, "modes": 20, "rtol": 1e-10}),
    Study("energy", "Energy conservation", cases.energy_conservation,
          quick={"steps": 2000}, full={"steps": 2000}),
    Study("time-step", "Time-step convergence", cases.time_step_convergence),
    Study("roughness", "ISO 8608 roughness", cases.iso8608_roughness,
          quick={"length": 1000.0}, full={"length": 1000.0}),
    Study("mesh", "Mesh convergence", cases.mesh_convergence),
    Study("parked-vehicle", "Parked vehicle", cases.parked_vehicle),
    Study("benscoter", "Shear-deformable warping (Benscoter)", cases.benscoter_torsion),
    Study("paper-torsion-theories", "Paper case: Vlasov and Benscoter torsion", cases.paper_torsion_theories,
          quick={"dt": 0.005}, full={"dt": 0.005}),
    Study("vbi2d", "VBI-2D sprung vehicle (Euler-Bernoulli beam)", cases.vbi2d_sprung_vehicle,
          quick={"modes": 10, "rtol": 1e-8}, full={"modes": 20, "rtol": 1e-10}),
)


def study_names() -> list[str]:
    """Names of the studies, in run order (each yields one or more cases)."""
    return [s.name for s in STUDIES]


def study(name: str) -> Study:
    """The study called ``name``.

    Raises:
        CosimError: no such study.
    """
    for s in STUDIES:
        if s.name == name:
            return s
    raise CosimError(f"unknown validation study {name!r} (known: {', '.join(study_names())})")


def select(only: Sequence[str] | None, studies: Sequence[Study] = STUDIES) -> list[Study]:
    """``studies`` restricted to the names in ``only`` (all of them for None), in their order.

    Raises:
        CosimError: ``only`` names an unknown study.
    """
    if only is None:
        return list(studies)
    if isinstance(only, str):
        only = [only]
    known = [s.name for s in studies]
    unknown = [name for name in only if name not in known]
    if unknown:
        raise CosimError(f"unknown validation studies {unknown} (known: {', '.join(known)})")
    return [s for s in studies if s.name in only]
