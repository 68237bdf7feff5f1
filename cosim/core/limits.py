"""Resource limits: how large an input may make cosim before it allocates (docs/limits.md).

Every input is untrusted, so every size that an input controls is checked
against a limit *before* the memory or time is spent: the finite-element
model's DOFs, the section mesh, the road grid, a study's runs, a run's time
steps, and what a log may make the reader decompress or hold. A limit error
names the key that asked for too much, the limit, and how to raise it: each
limit is an environment variable (``COSIM_MAX_...``) read when it is checked,
so ``COSIM_MAX_DOFS=500000 cosim run big.toml`` raises it for one command.

The defaults are far above what the bundled scenarios and studies use and far
below what exhausts a 24 GB machine.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from cosim.errors import ConfigError


@dataclass(frozen=True)
class Limit:
    """One limit: its environment variable, its default, its unit and what it bounds."""

    variable: str
    default: int
    unit: str
    what: str

    def value(self) -> int:
        """The limit in force: the environment variable if set (an integer >= 1), else the default.

        Raises:
            ConfigError: the variable is set but is not an integer >= 1.
        """
        text = os.environ.get(self.variable)
        if text is None or text.strip() == "":
            return self.default
        try:
            value = int(text)
        except ValueError:
            try:
                number = float(text)  # 5e5 is a fine way to write it
            except ValueError:
                number = 0.0
            value = int(number) if number.is_integer() else 0
        if value < 1:
            raise ConfigError(f"environment variable {self.variable}: expected an integer >= 1 (got {text!r})")
        return value

    def how_to_raise(self) -> str:
        return f"raise it with the environment variable {self.variable}"

    def check(self, amount: float, key: str, explain: str = "") -> None:
        """Raise :class:`ConfigError` when ``amount`` exceeds the limit.

        Args:
            amount: what the input asks for, in :attr:`unit`.
            key: the key (or file and key) that asks for it, first in the message.
            explain: how ``amount`` follows from the input, e.g. "40 elements per span x 3 spans".
        """
        limit = self.value()
        if amount > limit:
            how = f" ({explain})" if explain else ""
            raise ConfigError(f"{key}: {_count(amount)} {self.unit}{how} is more than the limit of {_count(limit)} "
                              f"{self.unit} for {self.what}; {self.how_to_raise()}")


def _count(value: float) -> str:
    return f"{int(value):,}" if value < 1e15 else f"{value:.3g}"


#: Degrees of freedom of the finite-element bridge model (7 per node).
MAX_DOFS = Limit("COSIM_MAX_DOFS", 200_000, "DOFs", "the bridge model (7 per node)")
#: Triangles of the finite-element section mesh (estimated as section area / mesh_size).
MAX_SECTION_TRIANGLES = Limit("COSIM_MAX_SECTION_TRIANGLES", 200_000, "triangles", "the section mesh")
#: Grid points of a road profile (per wheel path, times the wheel paths).
MAX_ROAD_POINTS = Limit("COSIM_MAX_ROAD_POINTS", 20_000_000, "grid points", "the road profiles (all wheel paths)")
#: Bytes of a road profile file read.
MAX_ROAD_FILE_BYTES = Limit("COSIM_MAX_ROAD_FILE_BYTES", 256 * 1024 * 1024, "bytes", "a road profile file")
#: Time steps of one run or replay (duration / dt).
MAX_STEPS = Limit("COSIM_MAX_STEPS", 500_000_000, "time steps", "one run")
#: Runs of one study (the product of its axes' lengths).
MAX_RUNS = Limit("COSIM_MAX_RUNS", 10_000, "runs", "one study")
#: Decompressed bytes of one chunk of a log.
MAX_CHUNK_BYTES = Limit("COSIM_MAX_CHUNK_BYTES", 64 * 1024 * 1024, "bytes", "one decompressed chunk of a log")
#: Bytes of one attachment of a log, and of all of them together.
MAX_ATTACHMENT_BYTES = Limit("COSIM_MAX_ATTACHMENT_BYTES", 1024 * 1024 * 1024, "bytes",
                            "the attachments of a log (together)")
#: Bytes of one record of a log outside the chunks (metadata, schemas, ...), attachments aside.
MAX_RECORD_BYTES = Limit("COSIM_MAX_RECORD_BYTES", 64 * 1024 * 1024, "bytes", "one record of a log")
#: Records (vehicles) of one WIM record file: streamed in constant memory, so this bounds the time a file takes.
MAX_WIM_RECORDS = Limit("COSIM_MAX_WIM_RECORDS", 200_000_000, "records", "one WIM record file")

#: Points of a deck given by its modes (a modes file, an importer; docs/modal-decks.md).
MAX_DECK_POINTS = Limit("COSIM_MAX_DECK_POINTS", 200_000, "points", "the deck points of a modal deck")
#: Modes of a deck given by its modes.
MAX_DECK_MODES = Limit("COSIM_MAX_DECK_MODES", 5_000, "modes", "the modes of a modal deck")
#: Numbers of one array of a modal deck (modes x points), and of its interpolation grid (modes x grid nodes).
MAX_MODE_VALUES = Limit("COSIM_MAX_MODE_VALUES", 20_000_000, "values",
                        "one array of a modal deck (modes x points, or modes x interpolation nodes)")
#: Bytes of a modes file (the .npz, or each file of the CSV form).
MAX_MODES_FILE_BYTES = Limit("COSIM_MAX_MODES_FILE_BYTES", 1024 * 1024 * 1024, "bytes", "a modes file")

ALL_LIMITS: tuple[Limit, ...] = (MAX_DOFS, MAX_SECTION_TRIANGLES, MAX_ROAD_POINTS, MAX_ROAD_FILE_BYTES, MAX_STEPS,
                                 MAX_RUNS, MAX_CHUNK_BYTES, MAX_ATTACHMENT_BYTES, MAX_RECORD_BYTES, MAX_WIM_RECORDS,
                                 MAX_DECK_POINTS, MAX_DECK_MODES, MAX_MODE_VALUES, MAX_MODES_FILE_BYTES)
