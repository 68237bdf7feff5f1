"""``cosim validate``: verification cases against closed forms, the paper's validation case, and the report.

- :mod:`~cosim.validation.references`: closed-form and independent reference solutions;
- :mod:`~cosim.validation.thin_walled`: the classical thin-walled section constants, the FE section solver's check;
- :mod:`~cosim.validation.cases`: the studies, computing only (frozen results, no drawing);
- :mod:`~cosim.validation.registry`: the one list of studies with their quick and full settings,
  shared by ``cosim validate`` and ``tests/verification``;
- :mod:`~cosim.validation.report`: :func:`run_validation`, the Markdown report and its figures
  (drawn by :mod:`cosim.plots`).

Importing this package does not import matplotlib.
"""
from .registry import STUDIES, Study, study, study_names
from .report import ProgressCallback, ValidationReport, run_validation, write_report
from .results import CaseResult, FigureData, StudyResult, Table

__all__ = [
    "STUDIES",
    "CaseResult",
    "FigureData",
    "ProgressCallback",
    "Study",
    "StudyResult",
    "Table",
    "ValidationReport",
    "run_validation",
    "study",
    "study_names",
    "write_report",
]
