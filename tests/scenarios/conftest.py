"""The fixtures of cosim's pytest plugin (:mod:`cosim.testing`) for this folder.

An installed cosim provides them everywhere through its ``pytest11`` entry
point (``cosim = "cosim.testing"``). Importing them here as well keeps these
tests working from an install made before that entry point existed: the names
are the same and this folder's copies take precedence. Without the entry
point, ``--cosim-update-logs`` is not a known option; ``COSIM_UPDATE_LOGS=1``
does the same.
"""
from cosim.testing import cosim_bridge, cosim_log_snapshot, run_scenario  # noqa: F401
