"""The study's one door to run logs: every log-reading name the study uses is imported here, and only here.

A run's log is reduced to its row by :mod:`cosim.study.table` and judged
complete (resume) by :mod:`cosim.study.execute` through these three functions.
"""
from __future__ import annotations

import os
from typing import Sequence

import numpy as np

from cosim.core.traffic import FrameTraffic
from cosim.log.writer import TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES, file_is_complete, read_log, traffic_from_log
from cosim.run.logged import sensor_series

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
    contents = read_log(path, topics=[TOPIC_TRAFFIC, TOPIC_VEHICLE_TYPES])
    return traffic_from_log(contents, length, step, until=until)
