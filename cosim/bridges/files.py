"""Modes files: a ``.npz`` or a folder of CSV files, read into a :class:`~cosim.core.modal_deck.ModalDeck` and
written from one (docs/modal-decks.md).

Every modes file is untrusted: its size is checked before it is read, an
``.npz``'s array headers (shape, type) before any array is loaded (a member
that holds Python objects is refused: nothing is unpickled), and a CSV file is
parsed line by line into arrays whose size the points and modes files fixed.
A bad file is one line that names the file and the array (or the CSV file,
line and column), what was expected and how to fix it.
"""
from __future__ import annotations

import csv
import math
import os
import shutil
import tempfile
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.core.checks import one_of
from cosim.core.limits import MAX_DECK_MODES, MAX_DECK_POINTS, MAX_MODE_VALUES, MAX_MODES_FILE_BYTES
from cosim.core.modal_deck import FRAMES, MAX_QUANTITIES, MODAL_QUANTITIES, QUANTITY_KEY, ModalDeck
from cosim.errors import ConfigError, first_line

__all__ = ["CSV_FILES", "NPZ_ARRAYS", "read_modes", "write_modes"]

#: The arrays of a ``.npz`` modes file (besides ``<quantity>:<sensor>`` arrays) and what each holds.
NPZ_ARRAYS: dict[str, str] = {
    "x": "(n,) deck points, m (bridge frame: along the bridge from the first support line)",
    "y": "(n,) deck points, m (bridge frame: lateral, positive to the left looking along +x)",
    "f_hz": "(m,) natural frequencies, Hz, ascending",
    "phi": "(m, n) vertical displacement (z up) of each mass-normalised mode at each point",
    "phi_x": "(m, n) dphi/dx at each point, the limit from +x (optional, bridge frame)",
    "phi_x_minus": "(m, n) dphi/dx, the limit from -x where the slope jumps (optional, needs phi_x)",
    "zeta": "(m,) modal damping ratios (optional)",
    "modal_mass": "(m,) generalised mass of each shape as stored, 1 for mass-normalised (optional)",
    "triangles": "(k, 3) the deck's surface as triangles of 0-based point indices (optional)",
    "frame": "'bridge' or 'network' (optional; a string)",
}
#: The files of the CSV form, and their columns (optional ones in brackets).
CSV_FILES: dict[str, str] = {
    "points.csv": "point,x,y",
    "modes.csv": "mode,f_hz[,zeta][,modal_mass]",
    "shapes.csv": "mode,point,w[,w_x | theta_y][,w_x_minus]",
    "triangles.csv": "a,b,c (optional file)",
    "quantities.csv": "mode,quantity,sensor,value (optional file)",
}
#: Longest point label of the CSV form.
MAX_LABEL = 64


# ================================================================================================ reading
def read_modes(path: str | os.PathLike[str], frame: str | None = None) -> ModalDeck:
    """A modes file: a ``.npz`` (arrays of :data:`NPZ_ARRAYS`) or a folder of CSV files (:data:`CSV_FILES`).

    Args:
        path: the ``.npz`` file or the folder.
        frame: the frame of the points ("bridge" or "network"; a scenario's ``[bridge] frame``); None: the
            file's ``frame``, else "bridge". A file that states another frame is an error.

    Raises:
        ConfigError: one line naming the file and the array (or CSV file, line and column).
    """
    p = Path(path)
    name = os.fspath(path)
    if frame is not None:
        one_of(frame, FRAMES, "frame", f"{name}: ")
    if p.is_dir():
        return _read_csv(p, name, frame)
    if not p.is_file():
        raise ConfigError(f"{name}: no such modes file (a .npz file, or a folder of CSV files: "
                          f"{', '.join(CSV_FILES)}); check the path")
    if p.suffix.lower() != ".npz":
        raise ConfigError(f"{name}: a modes file is a .npz file or a folder of CSV files (docs/modal-decks.md); "
                          f"got a {p.suffix or 'file without a suffix'}")
    return _read_npz(p, name, frame)


def _size(p: Path, name: str) -> None:
    MAX_MODES_FILE_BYTES.check(p.stat().st_size, name)


def _npz_headers(p: Path, name: str) -> dict[str, tuple[tuple[int, ...], np.dtype[Any]]]:
    """Each member's shape and type, read from its header (no array is loaded)."""
    headers: dict[str, tuple[tuple[int, ...], np.dtype[Any]]] = {}
    try:
        with zipfile.ZipFile(p) as archive:
            members = archive.infolist()
            if len(members) > len(NPZ_ARRAYS) + MAX_QUANTITIES:
                raise ConfigError(f"{name}: {len(members):,} arrays; a modes file has at most "
                                  f"{len(NPZ_ARRAYS) + MAX_QUANTITIES:,}")
            for info in members:
                key = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    if version == (1, 0):
                        shape, _, dtype = np.lib.format.read_array_header_1_0(member)
                    elif version == (2, 0):
                        shape, _, dtype = np.lib.format.read_array_header_2_0(member)
                    else:
                        raise ConfigError(f"{name}: {key}: .npy format version {version} is not read; save the "
                                          "file with numpy.savez")
                headers[key] = (tuple(int(s) for s in shape), dtype)
    except ConfigError:
        raise
    except (zipfile.BadZipFile, zlib.error, ValueError, EOFError, OSError, KeyError) as exc:
        raise ConfigError(f"{name}: not a readable .npz file ({first_line(exc)}); write it with numpy.savez or "
                          "cosim.bridges.write_modes") from None
    return headers


def _read_npz(p: Path, name: str, frame: str | None) -> ModalDeck:
    _size(p, name)
    headers = _npz_headers(p, name)
    for key, (shape, dtype) in headers.items():
        if key not in NPZ_ARRAYS and not QUANTITY_KEY.match(key):
            raise ConfigError(f"{name}: {key}: not an array of a modes file (expected {', '.join(NPZ_ARRAYS)} "
                              "or '<quantity>:<sensor>' modal values)")
        if dtype.hasobject:
            raise ConfigError(f"{name}: {key}: holds Python objects, which cosim never unpickles; save numbers "
                              "(and the frame as a plain string)")
        kinds = "U" if key == "frame" else "iu" if key == "triangles" else "fiu"
        if dtype.kind not in kinds:
            want = "a string" if key == "frame" else "integers" if key == "triangles" else "numbers"
            raise ConfigError(f"{name}: {key}: expected {want} (got dtype {dtype})")
        MAX_MODE_VALUES.check(math.prod(shape), f"{name}: {key}", f"an array of shape {shape}")
    for key in ("x", "y", "f_hz", "phi"):
        if key not in headers:
            raise ConfigError(f"{name}: {key}: missing; a modes file needs x, y, f_hz and phi "
                              f"({key}: {NPZ_ARRAYS[key]})")
    for key in ("x", "y"):
        MAX_DECK_POINTS.check(math.prod(headers[key][0]), f"{name}: {key}")
    MAX_DECK_MODES.check(math.prod(headers["f_hz"][0]), f"{name}: f_hz")
    arrays: dict[str, npt.NDArray[Any]] = {}
    try:
        with np.load(p, allow_pickle=False) as data:
            for key in headers:
                arrays[key] = np.asarray(data[key])
    except (zipfile.BadZipFile, zlib.error, ValueError, EOFError, OSError) as exc:
        raise ConfigError(f"{name}: not a readable .npz file ({first_line(exc)}); write it with numpy.savez or "
                          "cosim.bridges.write_modes") from None
    x, y = arrays.pop("x"), arrays.pop("y")
    if x.ndim != 1 or y.shape != x.shape:
        raise ConfigError(f"{name}: y: expected the shape of x, (n,) one per deck point (got x {x.shape}, "
                          f"y {y.shape})")
    file_frame = None
    if "frame" in arrays:
        text = arrays.pop("frame")
        file_frame = str(text.reshape(-1)[0]) if text.size == 1 else ""
        if file_frame not in FRAMES:
            raise ConfigError(f"{name}: frame: expected 'bridge' or 'network' (got {file_frame!r})")
        if frame is not None and frame != file_frame:
            raise ConfigError(f"{name}: frame: the file's points are in the {file_frame} frame, but frame = "
                              f"{frame!r} was asked for; give the frame the points are in")
    fields = {k: arrays.pop(k) for k in list(arrays) if k in NPZ_ARRAYS}
    return ModalDeck(points=np.column_stack([x.astype(float), y.astype(float)]), frame=frame or file_frame or "bridge",
                     quantities=arrays, source=name, **fields)


# -------------------------------------------------------------------------------------------- CSV form
class _Table:
    """One CSV file of the CSV form: its header checked, then its rows (line number, fields by column)."""

    def __init__(self, folder: Path, file: str, name: str, required: tuple[str, ...], optional: tuple[str, ...]):
        self.path = folder / file
        self.where = f"{os.path.join(name, file)}"
        _size(self.path, self.where)
        self.required, self.optional = required, optional
        self.columns: list[str] = []

    def rows(self) -> Iterator[tuple[int, dict[str, str]]]:
        with open(self.path, encoding="utf-8-sig", newline="") as handle:
            reader = csv.reader(handle)
            header: list[str] | None = None
            try:
                for fields in reader:
                    if not fields or all(not f.strip() for f in fields) or fields[0].lstrip().startswith("#"):
                        continue
                    if header is None:
                        header = [f.strip().lower() for f in fields]
                        self._check_header(header, reader.line_num)
                        self.columns = header
                        continue
                    if len(fields) != len(header):
                        raise ConfigError(f"{self.where}:{reader.line_num}: expected {len(header)} fields "
                                          f"({','.join(header)}), got {len(fields)}")
                    yield reader.line_num, {h: f.strip() for h, f in zip(header, fields)}
            except csv.Error as exc:
                raise ConfigError(f"{self.where}:{reader.line_num}: not a CSV file ({first_line(exc)})") from None
            except UnicodeDecodeError as exc:
                raise ConfigError(f"{self.where}: not a text file in UTF-8 ({first_line(exc)}); export the table "
                                  "as CSV in UTF-8") from None
            if header is None:
                raise ConfigError(f"{self.where}: empty; expected the header line {','.join(self.required)}")

    def _check_header(self, header: list[str], line: int) -> None:
        known = self.required + self.optional
        for column in header:
            if column not in known:
                raise ConfigError(f"{self.where}:{line}: unknown column {column!r}; the columns are "
                                  f"{', '.join(self.required)} and optionally {', '.join(self.optional) or '-'}")
        if len(set(header)) != len(header):
            raise ConfigError(f"{self.where}:{line}: a column appears twice in the header")
        missing = [c for c in self.required if c not in header]
        if missing:
            raise ConfigError(f"{self.where}:{line}: missing column {', '.join(missing)}; the header is "
                              f"{','.join(self.required)}" + (f" [,{',optional '.join(self.optional)}]"
                                                              if self.optional else ""))

    def number(self, text: str, column: str, line: int) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
            if text:
                raise ConfigError(f"{self.where}:{line}: {column}: expected a number, got {text!r}") from None
        if not math.isfinite(value):
            raise ConfigError(f"{self.where}:{line}: {column}: expected a finite number, got {text!r}")
        return value

    def integer(self, text: str, column: str, line: int) -> int:
        value = self.number(text, column, line)
        if not value.is_integer():
            raise ConfigError(f"{self.where}:{line}: {column}: expected an integer, got {text!r}")
        return int(value)

    def label(self, text: str, column: str, line: int) -> str:
        if not text or len(text) > MAX_LABEL:
            raise ConfigError(f"{self.where}:{line}: {column}: expected a point label of 1 to {MAX_LABEL} "
                              f"characters, got {text!r}")
        return text


def _read_csv(folder: Path, name: str, frame: str | None) -> ModalDeck:
    for required in ("points.csv", "modes.csv", "shapes.csv"):
        if not (folder / required).is_file():
            raise ConfigError(f"{os.path.join(name, required)}: missing; the CSV form is a folder with "
                              f"{', '.join(CSV_FILES)} (docs/modal-decks.md)")
    labels, points = _points(_Table(folder, "points.csv", name, ("point", "x", "y"), ()))
    modes = _Table(folder, "modes.csv", name, ("mode", "f_hz"), ("zeta", "modal_mass"))
    f_hz, zeta, modal_mass = _modes(modes)
    m, n = len(f_hz), len(points)
    MAX_MODE_VALUES.check(m * n, os.path.join(name, "shapes.csv"), f"{m} modes x {n} points")
    shapes = _Table(folder, "shapes.csv", name, ("mode", "point", "w"), ("w_x", "theta_y", "w_x_minus"))
    phi, phi_x, phi_x_minus = _shapes(shapes, labels, m)
    triangles = None
    if (folder / "triangles.csv").is_file():
        triangles = _triangles(_Table(folder, "triangles.csv", name, ("a", "b", "c"), ()), labels)
    quantities: dict[str, npt.NDArray[np.float64]] = {}
    if (folder / "quantities.csv").is_file():
        quantities = _quantities(_Table(folder, "quantities.csv", name, ("mode", "quantity", "sensor", "value"),
                                        ()), m)
    return ModalDeck(points=points, f_hz=f_hz, phi=phi, frame=frame or "bridge", phi_x=phi_x,
                     phi_x_minus=phi_x_minus, zeta=zeta, modal_mass=modal_mass, triangles=triangles,
                     quantities=quantities, source=name)


def _points(table: _Table) -> tuple[dict[str, int], npt.NDArray[np.float64]]:
    labels: dict[str, int] = {}
    lines: dict[str, int] = {}
    xy: list[tuple[float, float]] = []
    limit = MAX_DECK_POINTS.value()
    for line, row in table.rows():
        label = table.label(row["point"], "point", line)
        if label in labels:
            raise ConfigError(f"{table.where}:{line}: point {label!r} appears twice (first on line {lines[label]}); "
                              "give each point once")
        if len(labels) >= limit:
            MAX_DECK_POINTS.check(len(labels) + 1, table.where)
        labels[label], lines[label] = len(xy), line
        xy.append((table.number(row["x"], "x", line), table.number(row["y"], "y", line)))
    if not xy:
        raise ConfigError(f"{table.where}: no points; one line per deck point: point,x,y")
    return labels, np.array(xy, dtype=float)


def _modes(table: _Table) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64] | None,
                                   npt.NDArray[np.float64] | None]:
    found: dict[int, tuple[int, float, float, float]] = {}
    limit = MAX_DECK_MODES.value()
    for line, row in table.rows():
        mode = table.integer(row["mode"], "mode", line)
        if mode in found:
            raise ConfigError(f"{table.where}:{line}: mode {mode} appears twice (first on line {found[mode][0]})")
        if not 1 <= mode <= limit:
            if mode >= 1:
                MAX_DECK_MODES.check(mode, f"{table.where}:{line}: mode")
            raise ConfigError(f"{table.where}:{line}: mode: expected a mode number 1, 2, ... (got {mode})")
        f = table.number(row["f_hz"], "f_hz", line)
        if not f > 0:
            raise ConfigError(f"{table.where}:{line}: f_hz: {f:g} Hz; natural frequencies must be > 0")
        zeta = table.number(row["zeta"], "zeta", line) if "zeta" in row else math.nan
        mass = table.number(row["modal_mass"], "modal_mass", line) if "modal_mass" in row else math.nan
        found[mode] = (line, f, zeta, mass)
    if not found:
        raise ConfigError(f"{table.where}: no modes; one line per mode: mode,f_hz")
    m = len(found)
    missing = sorted(set(range(1, m + 1)) - set(found))
    if missing:
        raise ConfigError(f"{table.where}: mode {missing[0]} is missing; the modes are numbered 1 ... {m}, each once")
    rows = [found[j] for j in range(1, m + 1)]
    for j in range(1, m):
        if rows[j][1] < rows[j - 1][1]:
            raise ConfigError(f"{table.where}:{rows[j][0]}: f_hz: mode {j + 1} ({rows[j][1]:g} Hz) is below mode "
                              f"{j} ({rows[j - 1][1]:g} Hz); number the modes by ascending frequency")
    f_hz = np.array([r[1] for r in rows])
    zetas = np.array([r[2] for r in rows]) if "zeta" in table.columns else None
    masses = np.array([r[3] for r in rows]) if "modal_mass" in table.columns else None
    return f_hz, zetas, masses


def _shapes(table: _Table, labels: dict[str, int], m: int) -> tuple[npt.NDArray[np.float64],
                                                                    npt.NDArray[np.float64] | None,
                                                                    npt.NDArray[np.float64] | None]:
    n = len(labels)
    phi = np.zeros((m, n))
    seen = np.zeros((m, n), dtype=bool)
    phi_x: npt.NDArray[np.float64] | None = None
    phi_x_minus: npt.NDArray[np.float64] | None = None
    slope_column = ""
    for line, row in table.rows():
        if phi_x is None and ("w_x" in row or "theta_y" in row):
            if "w_x" in row and "theta_y" in row:
                raise ConfigError(f"{table.where}: give the slope as w_x or as theta_y (w_x = -theta_y), not both")
            slope_column = "w_x" if "w_x" in row else "theta_y"
            phi_x = np.zeros((m, n))
        if phi_x_minus is None and "w_x_minus" in row:
            if not slope_column:
                raise ConfigError(f"{table.where}: w_x_minus (the slope from -x) needs w_x (the slope from +x)")
            phi_x_minus = np.zeros((m, n))
        mode = table.integer(row["mode"], "mode", line)
        if not 1 <= mode <= m:
            raise ConfigError(f"{table.where}:{line}: mode {mode} is not in modes.csv (modes 1 ... {m})")
        label = row["point"]
        if label not in labels:
            raise ConfigError(f"{table.where}:{line}: point {label!r} is not in points.csv")
        j, i = mode - 1, labels[label]
        if seen[j, i]:
            raise ConfigError(f"{table.where}:{line}: mode {mode} at point {label!r} appears twice")
        seen[j, i] = True
        phi[j, i] = table.number(row["w"], "w", line)
        if phi_x is not None:
            slope = table.number(row[slope_column], slope_column, line)
            phi_x[j, i] = slope if slope_column == "w_x" else -slope
        if phi_x_minus is not None:
            phi_x_minus[j, i] = table.number(row["w_x_minus"], "w_x_minus", line)
    gap = np.argwhere(~seen)
    if len(gap):
        j, i = (int(v) for v in gap[0])
        label = next(k for k, v in labels.items() if v == i)
        raise ConfigError(f"{table.where}: mode {j + 1} has no value at point {label!r}; give every mode at every "
                          f"point of points.csv ({m} x {n} lines)")
    return phi, phi_x, phi_x_minus


def _triangles(table: _Table, labels: dict[str, int]) -> npt.NDArray[np.int64]:
    out: list[tuple[int, int, int]] = []
    limit = 4 * MAX_DECK_POINTS.value()
    for line, row in table.rows():
        corners = []
        for column in ("a", "b", "c"):
            label = row[column]
            if label not in labels:
                raise ConfigError(f"{table.where}:{line}: {column}: point {label!r} is not in points.csv")
            corners.append(labels[label])
        if len(out) >= limit:
            MAX_DECK_POINTS.check((len(out) + 1) / 4, table.where, "triangles / 4")
        out.append((corners[0], corners[1], corners[2]))
    if not out:
        raise ConfigError(f"{table.where}: no triangles; give the deck's surface (a,b,c point labels per line) or "
                          "leave the file out")
    return np.array(out, dtype=np.int64)


def _quantities(table: _Table, m: int) -> dict[str, npt.NDArray[np.float64]]:
    out: dict[str, npt.NDArray[np.float64]] = {}
    seen: dict[str, npt.NDArray[np.bool_]] = {}
    for line, row in table.rows():
        key = f"{row['quantity']}:{row['sensor']}"
        match = QUANTITY_KEY.match(key)
        if match is None or match[1] not in MODAL_QUANTITIES:
            raise ConfigError(f"{table.where}:{line}: {key!r} is not '<quantity>:<sensor>' (quantity one of "
                              f"{', '.join(MODAL_QUANTITIES)}; sensor of letters, digits, '_', '.', '-')")
        mode = table.integer(row["mode"], "mode", line)
        if not 1 <= mode <= m:
            raise ConfigError(f"{table.where}:{line}: mode {mode} is not in modes.csv (modes 1 ... {m})")
        if key not in out:
            if len(out) >= MAX_QUANTITIES:
                raise ConfigError(f"{table.where}:{line}: more than {MAX_QUANTITIES:,} modal quantities")
            out[key], seen[key] = np.zeros(m), np.zeros(m, dtype=bool)
        if seen[key][mode - 1]:
            raise ConfigError(f"{table.where}:{line}: {key} of mode {mode} appears twice")
        seen[key][mode - 1] = True
        out[key][mode - 1] = table.number(row["value"], "value", line)
    for key, flags in seen.items():
        if not flags.all():
            raise ConfigError(f"{table.where}: {key} has no value for mode {int(np.argmin(flags)) + 1}; give one per "
                              "mode")
    return out


# ================================================================================================ writing
def write_modes(path: str | os.PathLike[str], deck: ModalDeck, *, force: bool = False) -> Path:
    """Write ``deck`` as a ``.npz`` (a path ending in .npz) or as the CSV form (any other path: a folder).

    Written to a temporary name beside ``path`` and renamed, so that a reader never sees half a file. The CSV
    form carries no frame: read it back with ``read_modes(path, frame=deck.frame)``.

    Raises:
        ConfigError: ``path`` exists and ``force`` is False.
    """
    target = Path(path)
    if target.exists() and not force:
        raise ConfigError(f"{os.fspath(path)}: already exists; refusing to overwrite it (force=True replaces it)")
    target.parent.mkdir(parents=True, exist_ok=True)
    if target.suffix.lower() == ".npz":
        handle, temp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".npz")
        os.close(handle)
        try:
            np.savez_compressed(temp, **_npz_arrays(deck))
            os.replace(temp, target)
        finally:
            if os.path.exists(temp):
                os.unlink(temp)
        return target
    temp_dir = Path(tempfile.mkdtemp(dir=target.parent, prefix=f".{target.name}."))
    try:
        _write_csv(temp_dir, deck)
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()
        os.replace(temp_dir, target)
    finally:
        if temp_dir.exists():
            shutil.rmtree(temp_dir)
    return target


def _npz_arrays(deck: ModalDeck) -> dict[str, Any]:
    arrays: dict[str, Any] = {"x": deck.points[:, 0], "y": deck.points[:, 1], "f_hz": deck.f_hz, "phi": deck.phi,
                              "frame": np.array(deck.frame)}
    for key in ("phi_x", "phi_x_minus", "zeta", "modal_mass", "triangles"):
        value = getattr(deck, key)
        if value is not None:
            arrays[key] = value
    arrays.update(deck.quantities)
    return arrays


def _write_csv(folder: Path, deck: ModalDeck) -> None:
    def write(file: str, header: list[str], rows: Iterator[list[object]]) -> None:
        with open(folder / file, "w", encoding="utf-8", newline="") as handle:
            writer = csv.writer(handle, lineterminator="\n")
            writer.writerow(header)
            writer.writerows([repr(v) if isinstance(v, float) else v for v in row] for row in rows)

    labels = [str(i + 1) for i in range(deck.n_points)]
    write("points.csv", ["point", "x", "y"],
          ([labels[i], float(x), float(y)] for i, (x, y) in enumerate(deck.points)))
    extra = [(k, getattr(deck, k)) for k in ("zeta", "modal_mass") if getattr(deck, k) is not None]
    write("modes.csv", ["mode", "f_hz", *(k for k, _ in extra)],
          ([j + 1, float(deck.f_hz[j]), *(float(a[j]) for _, a in extra)] for j in range(deck.n_modes)))
    slopes = [(k, a) for k, a in (("w_x", deck.phi_x), ("w_x_minus", deck.phi_x_minus)) if a is not None]
    write("shapes.csv", ["mode", "point", "w", *(k for k, _ in slopes)],
          ([j + 1, labels[i], float(deck.phi[j, i]), *(float(a[j, i]) for _, a in slopes)]
           for j in range(deck.n_modes) for i in range(deck.n_points)))
    if deck.triangles is not None:
        write("triangles.csv", ["a", "b", "c"], ([labels[int(i)] for i in tri] for tri in deck.triangles))
    if deck.quantities:
        write("quantities.csv", ["mode", "quantity", "sensor", "value"],
              ([j + 1, *key.split(":", 1), float(values[j])] for key, values in deck.quantities.items()
               for j in range(deck.n_modes)))
