"""Traffic-volume studies: a base scenario swept over demand, trucks, speed limit, loads, road and seeds, on Dask.

A study file (TOML, ``docs/studies.md`` documents every key) names a base
scenario and sweep axes; every combination of axis values is one *run*:

- ``sumo_config``: the SUMO demand, a bundled level (light, medium, heavy,
  congested) or the user's own ``.sumocfg``;
- ``vehicles_per_hour``: every ``<flow>`` of the demand gets this rate (the
  bundled demand has one flow per direction: vehicles per hour per direction);
- ``truck_share``: the probabilities of the heavy vTypes (vClass bus, coach,
  truck, trailer) of every ``vTypeDistribution`` are rescaled to sum to this
  share, the light ones to the rest;
- ``speed_limit``: the speed of every lane of the network (internal junction
  lanes aside), m/s;
- ``loads``: ``fixed`` (no ``[traffic.loads]``: each vehicle weighs what its
  vType says) or a WIM site model replacing the base's ``[traffic.loads]`` model;
- ``road_class``: smooth or an ISO 8608 class;
- ``seeds``: Monte Carlo repetitions; SUMO's seed, the road-profile seed and
  the loads' seed are all the run's seed.

For every run cosim writes the SUMO files and the scenario it generated into
``<output>/runs/<run id>/``, runs the scenario there into ``run.mcap`` and
reduces it to one row of results (``result.json``); the rows make
``<output>/results.csv`` and ``results.parquet``, and ``<output>/plots/`` gets
one PNG per statistic against every swept axis.

The modules, one concept each:

- :mod:`cosim.study.spec`: the study file, the sweep, run ids and each run's
  generated inputs (:class:`Study`, :class:`RunTask`);
- :mod:`cosim.study.execute`: one run (:func:`execute_run`), resuming, Dask,
  the whole study (:func:`run_study`);
- :mod:`cosim.study.table`: a run's row of statistics, the results table and its plots;
- :mod:`cosim.study.folder`: the output folder's file names and atomic writes;
- :mod:`cosim.study.logs`: the only module that reads logs.

The SUMO files are read and edited by :mod:`cosim.sumo.files`; the figures are
drawn by :mod:`cosim.plots`. Nothing here prints.
"""
from cosim.study.execute import (
    Progress,
    StudyOutcome,
    default_workers,
    execute_run,
    finished_row,
    run_study,
    summary_text,
)
from cosim.study.spec import AXES, RunTask, Study, load_study, parse_study
from cosim.study.table import plot_study, write_table

__all__ = [
    "AXES",
    "Progress",
    "RunTask",
    "Study",
    "StudyOutcome",
    "default_workers",
    "execute_run",
    "finished_row",
    "load_study",
    "parse_study",
    "plot_study",
    "run_study",
    "summary_text",
    "write_table",
]
