"""Solved sections kept between runs: the user's cache folder as a :class:`cosim.core.section.SectionStore`.

Solving a plate section (:func:`cosim.core.section.section_from_plates`) takes
a second or two, and a run solves the same section at every start. A
scenario's sections are kept in the user's cache folder
(:func:`cache_folder`), one file per section, named by the SHA-256 of its
definition (the plates, ``nu``, the mesh size), cosim's version and
sectionproperties' version: a new version of either solves again.

An entry is untrusted when read: it must be a numpy ``.npz`` of plain arrays
(no pickles) within :data:`MAX_ENTRY_BYTES`, name the key it was written for,
match the SHA-256 of its contents that it carries, and hold arrays of the
right shapes whose mesh has the section's area; anything else (a corrupt,
cut short, foreign or older entry) is ignored, the section solved again and
the entry replaced. Entries are written atomically (a temporary file renamed
over the name); the folder is kept under :data:`MAX_CACHE_BYTES` by removing
the least recently used entries. ``COSIM_CACHE_DIR`` names another folder;
``COSIM_CACHE_DIR=""`` turns the cache off.

The numerical core asks a store and never opens a file itself (docs/architecture.md): this adapter is the only
place that knows about folders, environment variables and file formats for sections.
"""
from __future__ import annotations

import contextlib
import functools
import hashlib
import io
import json
import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cosim.core.section import SectionField, SectionProperties

__all__ = ["CACHE_ENV", "MAX_CACHE_BYTES", "MAX_ENTRY_BYTES", "SectionCache", "cache_folder", "user_section_cache"]

#: The environment variable naming the cache folder ("" turns the cache off).
CACHE_ENV = "COSIM_CACHE_DIR"
#: An entry larger than this is not read (a section's mesh and fields take well under a megabyte).
MAX_ENTRY_BYTES = 64 << 20
#: The sections' folder is kept under this size, least recently used entries removed first.
MAX_CACHE_BYTES = 256 << 20
_FORMAT = "cosim-section-1"
_SCALARS = ("A", "y_c", "z_c", "I_y", "I_z", "I_yz", "y_s", "z_s", "J", "I_w", "A_sy", "A_sz", "I_ws")
_ARRAYS = ("nodes", "elements", "omega", "shear")


def cache_folder() -> Path | None:
    """Where solved sections are kept: ``$COSIM_CACHE_DIR``, else the user's cache folder (XDG's on Linux,
    ``~/Library/Caches`` on macOS, ``%LOCALAPPDATA%`` on Windows) + ``cosim/sections``; None when off."""
    given = os.environ.get(CACHE_ENV)
    if given is not None:
        return Path(given) / "sections" if given else None
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "cosim" / "sections"


@functools.cache
def _versions() -> str:
    from importlib.metadata import PackageNotFoundError, version

    from cosim import __version__

    try:
        solver = version("sectionproperties")
    except PackageNotFoundError:
        solver = "?"
    return f"cosim {__version__}, sectionproperties {solver}"


def _key(definition: str) -> str:
    return hashlib.sha256(repr((_FORMAT, _versions(), definition)).encode()).hexdigest()


def _digest(meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256(json.dumps(meta, sort_keys=True).encode())
    for name in _ARRAYS:
        a = arrays[name]
        h.update(f"{name}:{a.dtype.str}:{a.shape}".encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


@dataclass(frozen=True)
class SectionCache:
    """A folder of solved sections (a :class:`cosim.core.section.SectionStore`); see the module's docstring.

    Attributes:
        folder: where the entries are (made on the first save).
    """

    folder: Path

    def load(self, definition: str) -> SectionProperties | None:
        """The solved section of this definition, or None when it is not there or its entry is not sound."""
        key = _key(definition)
        path = self.folder / f"{key}.npz"
        try:
            if not 0 < path.stat().st_size <= MAX_ENTRY_BYTES:
                return None
            data = path.read_bytes()
            with np.load(io.BytesIO(data), allow_pickle=False) as npz:
                arrays = {name: npz[name] for name in (*_ARRAYS, "meta", "digest")}
            meta = json.loads(arrays.pop("meta").tobytes().decode())
            digest = arrays.pop("digest").tobytes().decode()
            if meta.get("format") != _FORMAT or meta.get("key") != key or digest != _digest(meta, arrays):
                return None
            section = _section(meta, arrays)
        except Exception:  # noqa: BLE001 - a missing, corrupt or foreign entry: solved again, never trusted
            return None
        with contextlib.suppress(OSError):
            os.utime(path)  # recently used
        return section

    def save(self, definition: str, section: SectionProperties) -> None:
        """Keep a solved section (with its stress field); a folder that cannot be written is skipped."""
        field = section.stress_field
        if field is None:
            return
        key = _key(definition)
        arrays = {"nodes": np.asarray(field.nodes, dtype=np.float64),
                  "elements": np.asarray(field.elements, dtype=np.int64),
                  "omega": np.asarray(field.omega, dtype=np.float64),
                  "shear": np.asarray(field.unit_shear, dtype=np.float64)}
        meta = {"format": _FORMAT, "key": key, "versions": _versions(), "source": section.source,
                "deck_y": [float(v) for v in section.deck_y],
                "scalars": {name: float(getattr(section, name)) for name in _SCALARS}}
        buffer = io.BytesIO()
        np.savez(buffer, meta=np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8),
                 digest=np.frombuffer(_digest(meta, arrays).encode(), dtype=np.uint8), nodes=arrays["nodes"],
                 elements=arrays["elements"], omega=arrays["omega"], shear=arrays["shear"])
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            _write_atomically(self.folder / f"{key}.npz", buffer.getvalue())
            _bound(self.folder)
        except OSError:
            return


def user_section_cache() -> SectionCache | None:
    """The user's cache of solved sections (:func:`cache_folder`); None when turned off."""
    folder = cache_folder()
    return None if folder is None else SectionCache(folder)


def _section(meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> SectionProperties:
    values = {name: float(meta["scalars"][name]) for name in _SCALARS}
    nodes = np.asarray(arrays["nodes"], dtype=np.float64)
    elements = np.asarray(arrays["elements"], dtype=np.int64)
    omega = np.asarray(arrays["omega"], dtype=np.float64)
    shear = np.asarray(arrays["shear"], dtype=np.float64)
    if not (nodes.ndim == 2 and nodes.shape[1] == 2 and elements.ndim == 2 and elements.shape[1] == 6
            and omega.shape == (len(nodes),) and shear.shape == (len(nodes), 3, 2)
            and len(elements) and elements.min() >= 0 and elements.max() < len(nodes)):
        raise ValueError("arrays of the wrong shape")
    a, b, c = (nodes[elements[:, k]] for k in range(3))
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])).sum()
    if not abs(area - values["A"]) <= 1e-9 * values["A"]:  # the mesh is the section's (straight-sided Tri6)
        raise ValueError("a mesh of another area")
    for array in (nodes, elements, omega, shear):
        array.setflags(write=False)
    field = SectionField(nodes=nodes, elements=elements, omega=omega, shear=shear)
    y_min, y_max = (float(v) for v in meta["deck_y"])
    v = values
    return SectionProperties(A=v["A"], y_c=v["y_c"], z_c=v["z_c"], I_y=v["I_y"], I_z=v["I_z"], I_yz=v["I_yz"],
                             y_s=v["y_s"], z_s=v["z_s"], J=v["J"], I_w=v["I_w"], A_sy=v["A_sy"], A_sz=v["A_sz"],
                             I_ws=v["I_ws"], deck_y=(y_min, y_max), source=str(meta["source"]), stress_field=field)


def _write_atomically(path: Path, data: bytes) -> None:
    """``path`` holds ``data`` whole or is left as it was: written to a temporary file beside it, then renamed."""
    fd, temporary = tempfile.mkstemp(prefix=f".{path.stem[:16]}-", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def _bound(folder: Path) -> None:
    """Remove the least recently used entries until the folder is under :data:`MAX_CACHE_BYTES`."""
    entries = []
    for path in folder.glob("*.npz"):
        with contextlib.suppress(OSError):
            stat = path.stat()
            entries.append((stat.st_mtime, stat.st_size, path))
    total = sum(size for _, size, _ in entries)
    for _, size, path in sorted(entries):
        if total <= MAX_CACHE_BYTES:
            break
        with contextlib.suppress(OSError):
            path.unlink()
            total -= size
