"""Labelled monitoring datasets (``cosim dataset SPEC.toml``, docs/analysis.md §4): layer 4, like studies.

- :mod:`cosim.dataset.spec`: the dataset file (base scenario, windows, damage cases, temperature, instruments);
- :mod:`cosim.dataset.sensor_models`: what an instrument makes of a history (anti-aliasing, resampling, noise,
  quantisation);
- :mod:`cosim.dataset.build`: one logged run per window and case, and the table with its labels.
"""
from cosim.dataset.build import DATASET_FILE, DatasetOutcome, damaged_bridge, window_scenario, write_dataset
from cosim.dataset.sensor_models import SENSOR_TYPES, measure
from cosim.dataset.spec import Dataset, load_dataset, parse_dataset

__all__ = [
    "DATASET_FILE",
    "SENSOR_TYPES",
    "Dataset",
    "DatasetOutcome",
    "damaged_bridge",
    "load_dataset",
    "measure",
    "parse_dataset",
    "window_scenario",
    "write_dataset",
]
