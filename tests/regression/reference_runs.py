"""The runs whose logs were written before the package was reorganised (issue 9).

Each entry: a bundled scenario or an example file, and the overrides that keep
it short enough for the suite (SUMO runs end earlier than the full scenario,
logs are sampled at 20 Hz). The logs in ``logs/`` were written with the code
before the move, by the suite itself so that the numerical libraries run as
configured there (one BLAS thread from the process start: another threading
set-up changes the last bits of a few sums)::

    COSIM_WRITE_REFERENCE=1 python -m pytest tests/regression

Do not rewrite the logs to make a test pass: they are the "before". One was written anew on purpose:
``paper-bridge-traffic`` (issue 25, 2026-12-03), when the default scenario began to draw each vehicle's
loads from the Auxerre WIM model (``[traffic.loads]``). The log it had is kept as
``paper-bridge-traffic-fixed-weights``: the same scenario without ``[traffic.loads]`` (the vTypes' own
weights) still gives its numbers.
"""
from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parents[1] / "examples" / "scenarios"
LOGS = HERE / "logs"
WRITE_ENV = "COSIM_WRITE_REFERENCE"

#: Logged at 20 Hz to keep the stored logs small; the solver's steps are what they were.
SPARSE = {"every": None, "rate_hz": 20.0}

#: name -> (scenario: bundled name or path, overrides for cosim.testing.run)
RUNS: dict[str, tuple[str, dict]] = {
    "paper-double-tee": ("paper-double-tee", {"output": SPARSE}),
    "paper-double-tee-asymmetric": ("paper-double-tee-asymmetric", {"output": SPARSE}),
    "paper-bridge-traffic": ("paper-bridge-traffic", {"traffic": {"end": 75.0}, "output": SPARSE}),
    # The default scenario as it was before issue 25 (the vTypes' own weights): its log is the original one.
    "paper-bridge-traffic-fixed-weights": ("paper-bridge-traffic",
                                           {"traffic": {"end": 75.0, "loads": None}, "output": SPARSE}),
    "traffic-40m": (str(EXAMPLES / "traffic-40m.toml"), {"traffic": {"end": 75.0}, "output": SPARSE}),
    "congested-deck": (str(EXAMPLES / "congested-deck.toml"), {"traffic": {"end": 90.0}, "output": SPARSE}),
    "drive-by": (str(EXAMPLES / "drive-by.toml"), {"output": SPARSE}),
    "truck-40t-class-b": (str(EXAMPLES / "truck-40t-class-b.toml"), {"output": SPARSE}),
}
