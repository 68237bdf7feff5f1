"""The study's one door to run logs: every log-reading name the study uses is imported here, and only here.

A run's log is reduced to its row by :mod:`cosim.study.table` and judged
complete (resume) by :mod:`cosim.study.execute` through these three functions.
"""
from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from cosim.core.traffic import FrameTraffic
from cosim.log import file_is_complete, read_traffic, sensor_series

__all__ = ["log_is_complete", "logged_sensors", "logged_traffic"]


def log_is_complete(path: str | os.PathLike[str]) -> bool:
    """Whether the log was finished (summary and index written): a run cut short is not."""
    return file_is_complete(path)


def logged_sensors(path: str | os.PathLike[str], names: Sequence[str]) -> dict[str, np.ndarray]:
    """The logged samples of the named sensors, in time order."""
    _, series = sensor_series(path, names)
    return series


def logged_traffic(path: str | os.PathLike[str], length: float, step: float, until: float) -> FrameTraffic:
    """The SUMO frames of the log as a traffic source on a bridge of ``length`` (empty frames filled back in)."""
    traffic, _ = read_traffic(path, length, step, until=until)
    return traffic
