"""Grave's WIM-calibrated truck model: a site's parameter files, in SI, and draws from them (docs/loads.md).

A site is a folder of CSV files laid out as BTLS lays them out (BTLS manual,
"Traffic Data Input Files"; ``VehModelDataGrave.cpp``), each property a mixture
of up to three normals (rows: the modes; columns: weight, mean, sd per
property), blocks separated by a blank line:

=============  =======================================================  =========================
file           holds                                                    units in the file
=============  =======================================================  =========================
GVWpdf.csv     per direction (2 blocks): speed, then the GVW of 2-,     dm/s; 100 kg
               3-, 4- and 5-axle trucks
ASall.csv      per class (4 blocks): each axle spacing                   dm
AW2&3.csv      2- and 3-axle trucks (2 blocks): each axle's weight      relative (% of the GVW)
AW4&5.csv      4- and 5-axle trucks (2 blocks of 12 GVW ranges of       % of the GVW
               50 kN from 25 kN): mean W1, W2, WT, sd W1, W2, WT
               (WT: the tandem or tridem, shared equally)
CLASS%.csv     4 rows (2-5 axles) x 2 columns (directions)              % of the trucks
ATW.csv        optional: per class, each axle's track width (a null     cm
               mixture: the previous axle's)
FlowR.csv      optional: 24 rows (hours) x 2 columns (directions)       trucks/h
=============  =======================================================  =========================

The bounds are BTLS's (``VehicleGenGrave.cpp``): GVW in [35, 1000] x 100 kg,
axle weights in [15, 500] (of the files' relative unit), spacings in
[0.5, 200] dm, track widths in [120, 260] cm; masses become forces with
BTLS's 9.81 m/s^2.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from cosim.errors import ConfigError

from .draws import G, VehicleLoad, split, uniforms
from .mixture import NEGLIGIBLE, Mixture, MixtureSampler, Mode

CLASSES = (2, 3, 4, 5)  # Grave's truck classes: the axle count ("only vehicles with up to 5 axles")
GVW_BOUNDS = (35.0 * 100.0 * G, 1000.0 * 100.0 * G)  # N: [35, 1000] x 100 kg
SPACING_BOUNDS = (0.05, 20.0)  # m: [0.5, 200] dm
SHARE_BOUNDS = (0.15, 5.0)  # [15, 500] in the files' relative unit (% of the GVW), / 100
TRACK_BOUNDS = (1.2, 2.6)  # m: [120, 260] cm
SPEED_BOUNDS = (0.0, math.inf)  # m/s (BTLS does not bound speeds)
RANGE_START, RANGE_WIDTH, RANGES = 25e3, 50e3, 12  # AW4&5.csv's GVW ranges, N: range k >= 1 from 25 + 50 (k-1) kN
DEFAULT_TRACK_WIDTH = 1.90  # m: pybtls's default truck track width (190 cm) for a site without ATW.csv
WEIGHT_TOLERANCE = 0.01  # mode weights of a mixture add up to 1 within this (files give 2-3 decimals)
PERCENT_TOLERANCE = 0.5  # class percentages add up to 100 within this (files give 1-2 decimals)
MAX_FILE_BYTES = 1024 * 1024  # a parameter file is a few hundred bytes

#: The files a site folder holds (BTLS's names; matched without regard to case, as BTLS on Windows does).
FILES = ("GVWpdf.csv", "ASall.csv", "AW2&3.csv", "AW4&5.csv", "CLASS%.csv")
OPTIONAL_FILES = ("ATW.csv", "FlowR.csv")

SITES_PACKAGE = "cosim.core.loads"


@dataclass(frozen=True)
class GraveModel:
    """A site's Grave model, in SI units; :meth:`draw` draws a truck's loads from it.

    Indices: ``direction - 1`` (0, 1); ``truck_class - 2`` (0-3 for 2-5 axles).

    Attributes:
        name: the site's name (or the folder's).
        folder: where its files were read.
        class_mix: per direction, the probability of each class (2-5 axles), adding up to 1.
        gvw: per direction and class, the gross weight, N.
        speed: per direction, the trucks' speed, m/s (for information: SUMO drives the vehicles).
        spacings: per class, each axle spacing, m (class - 1 of them).
        axle_shares: for 2- and 3-axle trucks, each axle's relative weight (before scaling to the GVW).
        group_shares: for 4- and 5-axle trucks, per GVW range (12: below 25 kN, then 50 kN wide from
            25 kN, the last open), the relative weights of axle 1, axle 2 and the tandem/tridem.
        track_widths: per class, each axle's track width, m; None: the previous axle's.
        truck_flow: per direction, the mean truck flow of each hour of the day, trucks/h; None if the site
            has no FlowR.csv.
    """

    name: str
    folder: str
    class_mix: tuple[tuple[float, ...], ...]
    gvw: tuple[tuple[Mixture, ...], ...]
    speed: tuple[Mixture, ...]
    spacings: tuple[tuple[Mixture, ...], ...]
    axle_shares: tuple[tuple[Mixture, ...], ...]
    group_shares: tuple[tuple[tuple[Mixture, Mixture, Mixture], ...], ...]
    track_widths: tuple[tuple[Mixture | None, ...], ...]
    truck_flow: tuple[tuple[float, ...], ...] | None
    prepared: _Prepared = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "prepared", _Prepared.of(self))

    def draw(self, seed: int, vehicle_id: str, direction: int, truck_class: int | None = None) -> VehicleLoad:
        """One truck's axle count, spacings, axle loads and track widths.

        Args:
            seed: the scenario's seed (>= 0).
            vehicle_id: the vehicle's id: the draw depends only on (seed, id), not on order or process.
            direction: 1 or 2: whose class mix and GVW mixtures are used (each direction its own).
            truck_class: 2-5 axles; None: drawn from the direction's class mix.

        The GVW is drawn from the class and direction's mixture truncated to [35, 1000] x 100 kg, each
        spacing from its mixture truncated to [0.5, 200] dm, each relative axle weight truncated to
        [15, 500] (BTLS's bounds): a truncated mixture drawn exactly by inverse CDF, the same distribution
        as BTLS's redraw-until-inside loop, never a redraw. 2- and 3-axle trucks: each axle's weight from
        its mixture; 4- and 5-axle trucks: axle 1, axle 2 and the tandem/tridem from the normals of the
        GVW's range, the group shared equally by its axles. The axle loads are the weights scaled to add
        up to the GVW (exactly, to 1e-9).

        Raises:
            ConfigError: a direction other than 1 or 2, a class other than 2-5, a bad seed.
        """
        if direction not in (1, 2):
            raise ConfigError(f"direction: expected 1 or 2 (got {direction!r})")
        if truck_class is not None and truck_class not in CLASSES:
            raise ConfigError(f"truck class: expected 2, 3, 4 or 5 axles (got {truck_class!r})")
        ready = self.prepared
        u = iter(uniforms(seed, vehicle_id, "load", _UNIFORMS))
        pick = next(u)
        if truck_class is None:
            cumulative = ready.class_cumulative[direction - 1]
            c = 0
            while c < 3 and cumulative[c] <= pick:
                c += 1
            truck_class = CLASSES[c]
        n = truck_class
        gvw = ready.gvw[direction - 1][n - 2].draw(next(u), next(u))
        spacings = tuple(s.draw(next(u), next(u)) for s in ready.spacings[n - 2])
        if n <= 3:
            shares = [s.draw(next(u), next(u)) for s in ready.axle_shares[n - 2]]
        else:
            row = min(int((gvw - RANGE_START) / RANGE_WIDTH) + 1, RANGES - 1)
            w1, w2, group = (s.draw(next(u), next(u)) for s in ready.group_shares[n - 4][row])
            shares = [w1, w2] + [group / (n - 2)] * (n - 2)
        widths: list[float] = []
        for width in ready.track_widths[n - 2]:
            a, b = next(u), next(u)
            widths.append(widths[-1] if width is None else width.draw(a, b))
        return VehicleLoad(str(vehicle_id), n, direction, gvw, split(gvw, shares), spacings, tuple(widths))


_UNIFORMS = 1 + 2 + 2 * 4 + 2 * 5 + 2 * 5  # class, GVW, 4 spacings, 5 axle weights, 5 track widths at most


@dataclass(frozen=True)
class _Prepared:
    """A model's mixtures ready to draw (built once, when the model is made)."""

    class_cumulative: tuple[tuple[float, ...], ...]
    gvw: tuple[tuple[MixtureSampler, ...], ...]
    spacings: tuple[tuple[MixtureSampler, ...], ...]
    axle_shares: tuple[tuple[MixtureSampler, ...], ...]
    group_shares: tuple[tuple[tuple[MixtureSampler, ...], ...], ...]
    track_widths: tuple[tuple[MixtureSampler | None, ...], ...]

    @classmethod
    def of(cls, model: GraveModel) -> _Prepared:
        def cumulative(p: tuple[float, ...]) -> tuple[float, ...]:
            out, total = [], 0.0
            for value in p:
                total += value
                out.append(total)
            last = max(i for i, value in enumerate(p) if value > 0.0)
            return tuple(1.0 if i >= last else v for i, v in enumerate(out))

        return cls(
            tuple(cumulative(p) for p in model.class_mix),
            tuple(tuple(m.sampler() for m in per) for per in model.gvw),
            tuple(tuple(m.sampler() for m in per) for per in model.spacings),
            tuple(tuple(m.sampler() for m in per) for per in model.axle_shares),
            tuple(tuple(tuple(m.sampler() for m in row) for row in per) for per in model.group_shares),
            tuple(tuple(None if m is None else m.sampler() for m in per) for per in model.track_widths),
        )


# --------------------------------------------------------------------------- reading a site

def bundled_sites() -> tuple[str, ...]:
    """The names of the sites bundled with cosim (docs/loads.md#the-bundled-sites)."""
    root = resources.files(SITES_PACKAGE) / "sites"
    return tuple(sorted(p.name for p in root.iterdir() if p.is_dir() and not p.name.startswith(("_", "."))))


def load_model(model: str, base: Path | None = None) -> GraveModel:
    """A Grave model by a bundled site's name (``"Auxerre"``, any case) or a folder's path.

    Args:
        model: a bundled site's name, or the path of a folder of BTLS parameter files.
        base: the folder a relative path is taken from (the scenario file's); None: the working directory.

    Raises:
        ConfigError: neither a bundled site nor a folder (naming the sites), or a bad file (naming it,
            its line and column).
    """
    sites = {name.lower(): name for name in bundled_sites()}
    if model.lower() in sites:
        folder = Path(str(resources.files(SITES_PACKAGE) / "sites" / sites[model.lower()]))
        return read_site(folder, sites[model.lower()])
    folder = Path(model)
    if base is not None and not folder.is_absolute():
        folder = base / folder
    if not folder.is_dir():
        raise ConfigError(f"traffic.loads.model: {model!r} is neither a bundled site ({', '.join(sites.values())}) "
                          "nor a folder of BTLS parameter files (GVWpdf.csv, ASall.csv, ...); give one of them")
    return read_site(folder, folder.name)


def read_site(folder: Path, name: str) -> GraveModel:
    """Read and check a site folder (see the module's table), converting to SI."""
    found = {p.name.lower(): p for p in folder.iterdir() if p.is_file()}
    paths: dict[str, Path | None] = {}
    for wanted in FILES + OPTIONAL_FILES:
        path = found.get(wanted.lower())
        if path is None and wanted in FILES:
            raise ConfigError(f"{folder}: no {wanted}: a Grave model needs {', '.join(FILES)} "
                              f"({', '.join(OPTIONAL_FILES)} optional); add it or choose a bundled site")
        paths[wanted] = path

    def need(wanted: str) -> Path:
        path = paths[wanted]
        assert path is not None
        return path

    gvw_blocks = _blocks(need("GVWpdf.csv"), count=2, rows=3)
    speed = tuple(_mixture(need("GVWpdf.csv"), b, 0, 0.1, SPEED_BOUNDS, "m/s", f"direction {d + 1} speed")
                  for d, b in enumerate(gvw_blocks))
    gvw = tuple(tuple(_mixture(need("GVWpdf.csv"), b, 3 * c, 100.0 * G, GVW_BOUNDS, "N",
                               f"direction {d + 1} {c + 1}-axle GVW") for c in range(1, 5))
                for d, b in enumerate(gvw_blocks))
    as_blocks = _blocks(need("ASall.csv"), count=4, rows=3)
    spacings = tuple(tuple(_mixture(need("ASall.csv"), as_blocks[c - 2], 3 * j, 0.1, SPACING_BOUNDS, "m",
                                    f"{c}-axle spacing {j + 1}-{j + 2}") for j in range(c - 1)) for c in CLASSES)
    aw_blocks = _blocks(need("AW2&3.csv"), count=2, rows=3)
    axle_shares = tuple(tuple(_mixture(need("AW2&3.csv"), aw_blocks[c - 2], 3 * j, 0.01, SHARE_BOUNDS, "1",
                                       f"{c}-axle axle {j + 1} weight") for j in range(c)) for c in (2, 3))
    group_shares = tuple(_groups(need("AW4&5.csv"), block, c)
                         for c, block in zip((4, 5), _blocks(need("AW4&5.csv"), count=2, rows=RANGES)))
    atw = paths["ATW.csv"]
    if atw is None:
        default = Mixture((Mode(1.0, DEFAULT_TRACK_WIDTH, 0.0),), *TRACK_BOUNDS, "m")
        track_widths: tuple[tuple[Mixture | None, ...], ...] = tuple((default,) + (None,) * (c - 1) for c in CLASSES)
    else:
        atw_blocks = _blocks(atw, count=4, rows=3)
        track_widths = tuple(tuple(None if j > 0 and _null(atw, atw_blocks[c - 2], 3 * j) else
                                   _mixture(atw, atw_blocks[c - 2], 3 * j, 0.01, TRACK_BOUNDS, "m",
                                            f"{c}-axle axle {j + 1} track width")
                                   for j in range(c)) for c in CLASSES)
    flow = None if paths["FlowR.csv"] is None else _table(need("FlowR.csv"), 24, "trucks/h", "hour")
    return GraveModel(name, str(folder), _class_mix(need("CLASS%.csv")), gvw, speed, spacings, axle_shares,
                      group_shares, track_widths, flow)


Row = tuple[int, list[str]]  # (line number, fields)


def _rows(path: Path) -> list[Row]:
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ConfigError(f"{path}: {size:,} bytes is more than the {MAX_FILE_BYTES:,} bytes a Grave parameter "
                              "file may have (they are a few hundred); is this the right file?")
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ConfigError(f"{path}: not a text file; a Grave parameter file is comma-separated numbers") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read it ({exc.strerror})") from None
    out = []
    for number, line in enumerate(text.splitlines(), start=1):
        fields = [f.strip() for f in line.split(",")]
        while fields and fields[-1] == "":
            fields.pop()
        out.append((number, fields))
    return out


def _blocks(path: Path, count: int, rows: int) -> list[list[Row]]:
    """The file's blocks of non-blank rows (separated by blank ones), checked for their number and size."""
    blocks: list[list[Row]] = []
    current: list[Row] = []
    for row in _rows(path) + [(0, [])]:
        if row[1]:
            current.append(row)
        elif current:
            blocks.append(current)
            current = []
    if len(blocks) != count or any(len(b) != rows for b in blocks):
        shape = ", ".join(f"{len(b)} (from line {b[0][0]})" for b in blocks) or "none"
        raise ConfigError(f"{path}: expected {count} block(s) of {rows} rows separated by a blank line (BTLS's "
                          f"layout), found rows {shape}; fix the layout (docs/loads.md#the-parameter-files)")
    return blocks


def _number(path: Path, row: Row, column: int, what: str) -> float:
    number, fields = row
    text = fields[column] if column < len(fields) else ""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise ConfigError(f"{path}: line {number}, column {column + 1} ({what}): expected a number, got {text!r}")
    return value


def _null(path: Path, block: list[Row], column: int) -> bool:
    """ATW.csv: a mixture whose first mean is 0 means "the previous axle's width" (BTLS manual, ATW.csv)."""
    return abs(_number(path, block[0], column + 1, "track width mean")) <= 1e-6


def _mixture(path: Path, block: list[Row], column: int, scale: float, bounds: tuple[float, float], unit: str,
             what: str) -> Mixture:
    """The mixture in columns ``column`` .. ``column + 2`` (weight, mean, sd) of a block's rows, checked and in
    SI (``scale`` x the file's unit)."""
    modes = []
    for row in block:
        w = _number(path, row, column, f"{what}: mode weight")
        m = _number(path, row, column + 1, f"{what}: mean")
        s = _number(path, row, column + 2, f"{what}: standard deviation")
        where = f"{path}: line {row[0]}, columns {column + 1}-{column + 3} ({what})"
        if not 0.0 <= w <= 1.0 + WEIGHT_TOLERANCE:
            raise ConfigError(f"{where}: the mode weight {w:g} is not a probability; expected 0 to 1")
        if s < 0.0:
            raise ConfigError(f"{where}: the standard deviation {s:g} is negative; expected >= 0")
        modes.append(Mode(w, m * scale, s * scale))
    total = sum(mode.weight for mode in modes)
    lines = f"lines {block[0][0]}-{block[-1][0]}, column {column + 1}"
    if abs(total - 1.0) > WEIGHT_TOLERANCE:
        raise ConfigError(f"{path}: {lines} ({what}): the mode weights add up to {total:.4g}, not 1 (within "
                          f"{WEIGHT_TOLERANCE:g}); correct them so that they add up to 1")
    mixture = Mixture(tuple(Mode(m.weight / total, m.mean, m.sd) for m in modes), bounds[0], bounds[1], unit)
    if mixture.mass_inside() < NEGLIGIBLE:
        raise ConfigError(f"{path}: {lines} ({what}): no probability within BTLS's bounds "
                          f"[{bounds[0] / scale:g}, {bounds[1] / scale:g}] (in the file's unit); check the means")
    return mixture


def _groups(path: Path, block: list[Row], axles: int) -> tuple[tuple[Mixture, Mixture, Mixture], ...]:
    """AW4&5.csv's 12 GVW ranges for one class: normals of axle 1, axle 2 and the group (% of the GVW).

    A null row (all six values 0: no trucks measured in that range, as in the BTLS manual's own example)
    takes the nearest range with data, below it if there is one, else above it: BTLS would redraw a null
    normal for ever (``VehicleGenGrave.cpp``: ``while (val < 15 || val > 500)``)."""
    rows: list[tuple[Mixture, Mixture, Mixture] | None] = []
    for k, row in enumerate(block):
        values = [_number(path, row, j, f"{axles}-axle GVW range {k + 1}") for j in range(6)]
        if all(v == 0.0 for v in values):
            rows.append(None)
            continue
        normals = []
        for j, part in enumerate(("axle 1", "axle 2", "tandem/tridem")):
            mean, sd = values[j] * 0.01, values[j + 3] * 0.01
            if sd < 0.0:
                raise ConfigError(f"{path}: line {row[0]}, column {j + 4} ({axles}-axle {part} sd): "
                                  f"{values[j + 3]:g} is negative; expected >= 0")
            normal = Mixture((Mode(1.0, mean, sd),), *SHARE_BOUNDS, "1")
            if normal.mass_inside() < NEGLIGIBLE:
                raise ConfigError(f"{path}: line {row[0]}, columns {j + 1} and {j + 4} ({axles}-axle trucks, GVW "
                                  f"range {k + 1}, {part}): no probability within BTLS's bounds [15, 500] % of the "
                                  "GVW; give its mean and sd in % of the GVW")
            normals.append(normal)
        rows.append((normals[0], normals[1], normals[2]))
    if all(r is None for r in rows[1:]):
        raise ConfigError(f"{path}: lines {block[0][0]}-{block[-1][0]} ({axles}-axle trucks): every GVW range from "
                          "25 kN is null (all 0); give the axle weights of at least one range")
    filled = []
    for k in range(len(rows)):
        below = [r for r in rows[1:k + 1][::-1] if r is not None]
        above = [r for r in rows[k + 1:] if r is not None]
        nearest = rows[k] or (below[0] if below else above[0])
        filled.append(nearest)
    return tuple(filled)


def _table(path: Path, rows: int, unit: str, what: str) -> tuple[tuple[float, ...], ...]:
    """A block of ``rows`` rows x 2 columns (directions) of non-negative numbers, by direction."""
    (block,) = _blocks(path, count=1, rows=rows)
    columns: list[list[float]] = [[], []]
    for k, row in enumerate(block):
        for d in range(2):
            value = _number(path, row, d, f"{what} {k + 1}, direction {d + 1}, {unit}")
            if value < 0.0:
                raise ConfigError(f"{path}: line {row[0]}, column {d + 1}: {value:g} {unit} is negative; "
                                  "expected >= 0")
            columns[d].append(value)
    return tuple(tuple(c) for c in columns)


def _class_mix(path: Path) -> tuple[tuple[float, ...], ...]:
    """CLASS%.csv: rows 2-5 axles, columns the directions, in % -> probabilities per direction."""
    percent = _table(path, 4, "%", "class")
    out = []
    for d, column in enumerate(percent):
        total = sum(column)
        if abs(total - 100.0) > PERCENT_TOLERANCE:
            raise ConfigError(f"{path}: column {d + 1} (direction {d + 1}): the class percentages add up to "
                              f"{total:.4g} %, not 100 (within {PERCENT_TOLERANCE:g}); correct them")
        out.append(tuple(v / total for v in column))
    return tuple(out)
