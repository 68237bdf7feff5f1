"""Every figure cosim draws (matplotlib, Agg): the only module that imports matplotlib.

Functions take plain values (arrays, results) and a path, draw one figure
and write it; they neither read logs nor run anything. Callers check the
output path before the work (``cosim.run.outputs``).
"""
from __future__ import annotations

# --------------------------------------------------------------------------- common


# --------------------------------------------------------------------------- mode shapes


# --------------------------------------------------------------------------- logs (sensor time histories)


# --------------------------------------------------------------------------- studies


# --------------------------------------------------------------------------- validation
