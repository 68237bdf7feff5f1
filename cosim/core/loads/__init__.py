"""Real loads (issue 25): WIM records and Grave's WIM-calibrated load model, as plain data (docs/loads.md).

- :mod:`.records` (with the layouts of :mod:`.formats`): WIM record files in CASTOR, BeDIT, DITIS and MON,
  streamed and checked line by line (:func:`read_records`, :func:`survey`), and written (:func:`write_records`);
- :mod:`.grave`: a site's Grave model from BTLS's parameter files (:func:`load_model`; bundled sites in
  ``sites/``) and a truck's loads drawn from it (:meth:`GraveModel.draw`);
- :mod:`.draws`: what one vehicle gets (:class:`VehicleLoad`), cars' light distribution (:func:`draw_car`),
  lateral wander (:func:`wander`), and the per-vehicle random numbers they all come from (:func:`uniforms`);
- :mod:`.mixture`: the truncated normal mixtures behind them.

Everything is in SI units (N, m, s, m/s). Imports numpy, scipy, the standard library, :mod:`cosim.errors`
and the core's limits only: no SUMO, no MCAP, no configuration library.
"""
from __future__ import annotations

from .draws import (
    CAR,
    EN1991_2_FREQUENCIES,
    EN1991_2_OFFSETS,
    WANDER_WORDS,
    CarModel,
    VehicleLoad,
    draw_car,
    lane_wander,
    uniforms,
    wander,
)
from .formats import FORMATS, Format
from .grave import CLASSES, GraveModel, bundled_sites, load_model, read_site
from .mixture import Mixture, Mode
from .records import RecordsSummary, VehicleRecord, btls_lane, read_records, survey, write_records

__all__ = [
    "CAR", "CLASSES", "EN1991_2_FREQUENCIES", "EN1991_2_OFFSETS", "FORMATS", "CarModel", "Format", "GraveModel",
    "Mixture", "Mode", "RecordsSummary", "VehicleLoad", "VehicleRecord", "WANDER_WORDS", "btls_lane", "bundled_sites",
    "draw_car", "lane_wander", "load_model", "read_records", "read_site", "survey", "uniforms", "wander",
    "write_records",
]
