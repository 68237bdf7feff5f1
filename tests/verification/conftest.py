"""Fixtures for the verification tests: the registered validation studies, each computed once per session.

``cosim validate --quick`` and these tests run the same studies
(:data:`cosim.validation.STUDIES`) at the same quick settings.
"""
from __future__ import annotations

from collections.abc import Callable

import pytest

from cosim.validation import STUDIES, StudyResult, study


@pytest.fixture(scope="session")
def computed() -> Callable[[str], StudyResult]:
    """``computed(name)``: the registered study ``name`` at its quick settings, computed on first use."""
    cache: dict[str, StudyResult] = {}

    def get(name: str) -> StudyResult:
        if name not in cache:
            cache[name] = study(name).run(quick=True)
        return cache[name]

    return get


@pytest.fixture(scope="session")
def all_computed(computed: Callable[[str], StudyResult]) -> list[StudyResult]:
    """Every registered study, in report order."""
    return [computed(s.name) for s in STUDIES]
