"""The verification and validation cases of ``cosim validate``: computing only.

Every function here is one study of docs/validation.md -- the paper's 40 m
double-tee bridge (the paper's validation case there) or a closed-form or
independent reference of :mod:`cosim.validation.references` -- and returns a
frozen :class:`~cosim.validation.results.StudyResult`: its cases (error,
tolerance, the reference's source, the numbers behind the error) and the data
of its figures. Nothing here draws, writes or formats Markdown: the registry
(:mod:`cosim.validation.registry`) names the studies and their quick and full
settings, the report writer (:mod:`cosim.validation.report`) draws and writes,
and ``tests/verification`` asserts on the very same results::

    from cosim.validation.cases import fryba_moving_force

    for case in fryba_moving_force(steps=500).cases:
        print(case.name, case.error, case.tolerance, case.passed)

One module per topic: :mod:`.paper` (the paper's double-tee), :mod:`.statics`
(Timoshenko statics and frequencies), :mod:`.torsion` (Vlasov torsion),
:mod:`.moving_loads` (Fryba, the sprung mass), :mod:`.time_integration`
(energy, time-step convergence), :mod:`.roughness` (ISO 8608), :mod:`.mesh`
(mesh convergence), :mod:`.parked` (the parked vehicle) and :mod:`.theories`
(Benscoter torsion, the paper case under both torsions, VBI-2D). Errors are
measured in the unit each case names (usually relative to the reference's peak)
and compared with a tolerance stated, with its reason, in :mod:`.common`; cases
without a tolerance are informational. Every name is importable from here.
"""
from __future__ import annotations

from .common import (
    GRAVITY,
    TOL_BENSCOTER_FREQ,
    TOL_BENSCOTER_STATIC,
    TOL_ENERGY,
    TOL_FE_40,
    TOL_FREQ_TIMOSHENKO,
    TOL_FRYBA,
    TOL_NODAL_EXACT,
    TOL_ORDER_MESH_EB,
    TOL_ORDER_MESH_TIMOSHENKO,
    TOL_ORDER_TIME,
    TOL_PAPER_BASES,
    TOL_PARKED,
    TOL_ROUGHNESS,
    TOL_SPRUNG,
    TOL_VBI2D,
    TOL_VBI2D_PEAK_TIME,
)
from .mesh import MeshFigure, mesh_convergence
from .moving_loads import FrybaFigure, SprungMassFigure, fryba_moving_force, sprung_mass
from .paper import (
    PAPER_DURATION,
    PAPER_LANE_Y,
    PAPER_MODAL_MODES,
    PAPER_NODES,
    PAPER_QC1,
    PAPER_QC2,
    PAPER_QC2_ENTRY,
    PAPER_SPEED,
    PaperAsymmetricFigure,
    PaperNodeFigure,
    paper_case,
)
from .parked import ParkedFigure, parked_vehicle
from .roughness import RoughnessFigure, iso8608_roughness
from .statics import TimoshenkoStaticFigure, timoshenko_frequencies, timoshenko_static
from .theories import (
    BenscoterFigure,
    PaperTheoriesFigure,
    Vbi2dFigure,
    benscoter_torsion,
    paper_torsion_theories,
    vbi2d_sprung_vehicle,
)
from .time_integration import EnergyFigure, TimeStepFigure, energy_conservation, time_step_convergence
from .torsion import TorsionStaticFigure, lateral_torsional_frequencies, torsion_static, torsional_frequencies

__all__ = [
    # the studies
    "benscoter_torsion",
    "energy_conservation",
    "fryba_moving_force",
    "iso8608_roughness",
    "lateral_torsional_frequencies",
    "mesh_convergence",
    "paper_case",
    "paper_torsion_theories",
    "parked_vehicle",
    "sprung_mass",
    "time_step_convergence",
    "timoshenko_frequencies",
    "timoshenko_static",
    "torsion_static",
    "torsional_frequencies",
    "vbi2d_sprung_vehicle",
    # the data of their figures
    "BenscoterFigure",
    "EnergyFigure",
    "FrybaFigure",
    "MeshFigure",
    "PaperAsymmetricFigure",
    "PaperNodeFigure",
    "PaperTheoriesFigure",
    "ParkedFigure",
    "RoughnessFigure",
    "SprungMassFigure",
    "TimeStepFigure",
    "TimoshenkoStaticFigure",
    "TorsionStaticFigure",
    "Vbi2dFigure",
    # tolerances, gravity and the paper's set-up
    "GRAVITY",
    "TOL_BENSCOTER_FREQ",
    "TOL_BENSCOTER_STATIC",
    "TOL_ENERGY",
    "TOL_FE_40",
    "TOL_FREQ_TIMOSHENKO",
    "TOL_FRYBA",
    "TOL_NODAL_EXACT",
    "TOL_ORDER_MESH_EB",
    "TOL_ORDER_MESH_TIMOSHENKO",
    "TOL_ORDER_TIME",
    "TOL_PAPER_BASES",
    "TOL_PARKED",
    "TOL_ROUGHNESS",
    "TOL_SPRUNG",
    "TOL_VBI2D",
    "TOL_VBI2D_PEAK_TIME",
    "PAPER_DURATION",
    "PAPER_LANE_Y",
    "PAPER_MODAL_MODES",
    "PAPER_NODES",
    "PAPER_QC1",
    "PAPER_QC2",
    "PAPER_QC2_ENTRY",
    "PAPER_SPEED",
]
