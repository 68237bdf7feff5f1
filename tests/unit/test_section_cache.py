"""Solved sections kept between runs (cosim.run.section_cache): the same numbers as a solve, and an entry that is
corrupt, foreign, pickled, too large or of another mesh is solved again, never trusted; entries are written
atomically and the folder stays within its bound. Real solves, real files."""
from __future__ import annotations

import io
import json
import os

import numpy as np
import pytest

from cosim.core import section
from cosim.core.section import Plate, section_from_plates
from cosim.run import section_cache
from cosim.run.section_cache import SectionCache


def plates(t_web: float) -> list[Plate]:
    """A small I (a web thickness used by no other test, so that the first call solves)."""
    return [Plate((-0.3, 0.4), (0.3, 0.4), 0.05), Plate((0.0, -0.4), (0.0, 0.4), t_web),
            Plate((-0.3, -0.4), (0.3, -0.4), 0.05)]


@pytest.fixture
def cache(tmp_path):
    section_from_plates.cache_clear()  # the per-process cache: each call below asks the store
    yield SectionCache(tmp_path / "sections")
    section_from_plates.cache_clear()


def _solve_count(p: list[Plate], store: SectionCache | None) -> tuple[section.SectionProperties, int]:
    before = section.FE_SOLVES
    out = section_from_plates(p, store=store)
    section_from_plates.cache_clear()
    return out, section.FE_SOLVES - before


def _entries(cache: SectionCache) -> list:
    return sorted(cache.folder.glob("*.npz"))


def test_a_cached_section_is_the_solved_one_exactly(cache):
    solved, solves = _solve_count(plates(0.031), cache)
    assert solves == 1 and len(_entries(cache)) == 1
    cached, solves = _solve_count(plates(0.031), cache)
    assert solves == 0
    assert cached == solved  # every constant, bit for bit
    for name in ("nodes", "elements", "omega"):
        np.testing.assert_array_equal(getattr(cached.stress_field, name), getattr(solved.stress_field, name))
    np.testing.assert_array_equal(cached.stress_field.unit_shear, solved.stress_field.unit_shear)
    assert cached.stress_field.omega_at(0.0, 0.4) == solved.stress_field.omega_at(0.0, 0.4)
    np.testing.assert_array_equal(cached.stress_field.shear_at(0.0, 0.0), solved.stress_field.shear_at(0.0, 0.0))


def _rewrite(entry, change) -> None:
    """The entry with its arrays changed by ``change`` and written back as a well-formed npz."""
    with np.load(io.BytesIO(entry.read_bytes())) as npz:
        arrays = {k: npz[k].copy() for k in npz.files}
    change(arrays)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    entry.write_bytes(buffer.getvalue())


def _redigest(arrays: dict) -> None:
    """Make the entry's own digest match its (changed) contents: only the other checks can refuse it."""
    meta = json.loads(arrays["meta"].tobytes())
    digest = section_cache._digest(meta, {k: arrays[k] for k in ("nodes", "elements", "omega", "shear")})
    arrays["digest"] = np.frombuffer(digest.encode(), dtype=np.uint8)


def _moved_mesh(arrays: dict) -> None:
    arrays["nodes"][:, 0] *= 1.01
    _redigest(arrays)


def _flipped(arrays: dict) -> None:
    arrays["omega"][3] += 1e-9


def _pickled(arrays: dict) -> None:
    arrays.clear()
    arrays["meta"] = np.array([{"format": "cosim-section-1"}], dtype=object)


@pytest.mark.parametrize("damage", ["truncated", "flipped", "foreign", "pickled", "huge", "garbage", "moved mesh"])
def test_an_unsound_entry_is_solved_again_and_replaced(cache, damage, monkeypatch):
    solved, _ = _solve_count(plates(0.032), cache)
    (entry,) = _entries(cache)
    data = entry.read_bytes()
    if damage == "truncated":
        entry.write_bytes(data[: len(data) // 2])
    elif damage == "flipped":  # one number of the mesh changed: the entry's digest no longer matches
        _rewrite(entry, _flipped)
    elif damage == "moved mesh":  # a consistent digest, but a mesh that is not the section's area
        _rewrite(entry, _moved_mesh)
    elif damage == "foreign":  # another section's sound entry under this name
        _solve_count(plates(0.033), cache)
        other = next(p for p in _entries(cache) if p != entry)
        os.replace(other, entry)
    elif damage == "pickled":
        _rewrite(entry, _pickled)
    elif damage == "huge":
        monkeypatch.setattr(section_cache, "MAX_ENTRY_BYTES", len(data) - 1)
    else:
        entry.write_bytes(b"not a numpy file at all")
    again, solves = _solve_count(plates(0.032), cache)
    assert solves == 1 and again == solved
    if damage != "huge":
        cached, solves = _solve_count(plates(0.032), cache)  # the entry was written anew
        assert solves == 0 and cached == solved


def test_the_key_is_the_definition_and_the_versions(cache, monkeypatch):
    _solve_count(plates(0.034), cache)
    (entry,) = _entries(cache)
    with np.load(entry) as npz:
        meta = json.loads(npz["meta"].tobytes())
    assert meta["key"] == entry.stem and "cosim " in meta["versions"] and "sectionproperties" in meta["versions"]
    _, solves = _solve_count(list(reversed(plates(0.034))), cache)  # the same section, given in another order
    assert solves == 0
    _, solves = _solve_count(plates(0.034), SectionCache(cache.folder))  # another store on the same folder
    assert solves == 0
    monkeypatch.setattr(section_cache, "_versions", lambda: "cosim 99, sectionproperties 99")
    _, solves = _solve_count(plates(0.034), cache)
    assert solves == 1 and len(_entries(cache)) == 2  # another version: another entry


def test_an_entry_is_written_whole_or_not_at_all(cache, monkeypatch):
    """A write cut short (here: the rename fails, as after a crash before it, or a full disk) leaves the entry as
    it was, readable, and no temporary file behind."""
    solved, _ = _solve_count(plates(0.038), cache)
    cache.save("a definition", solved)
    assert len(_entries(cache)) == 2 and cache.load("a definition") == solved
    before = {p: p.read_bytes() for p in _entries(cache)}

    def fail(*_args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(section_cache.os, "replace", fail)
    cache.save("a definition", solved)  # written again: its rename fails
    cache.save("another definition", solved)  # a new entry: its rename fails
    assert {p: p.read_bytes() for p in _entries(cache)} == before
    assert cache.load("a definition") == solved and cache.load("another definition") is None
    assert not [p.name for p in cache.folder.iterdir() if p.suffix != ".npz"]


def test_the_folder_stays_within_its_bound(cache, monkeypatch):
    _solve_count(plates(0.035), cache)
    (first,) = _entries(cache)
    os.utime(first, (1.0, 1.0))  # the least recently used
    monkeypatch.setattr(section_cache, "MAX_CACHE_BYTES", first.stat().st_size + 10)
    _solve_count(plates(0.036), cache)
    assert len(_entries(cache)) == 1 and not first.exists()
    assert not list(cache.folder.glob("*.tmp"))


def test_scenarios_use_the_users_cache_folder_and_it_can_be_off(tmp_path, monkeypatch):
    from cosim.run.bridge_tables import PlateConfig, SectionConfig

    rows = [PlateConfig(start=p.start, end=p.end, thickness=p.thickness) for p in plates(0.037)]
    config = SectionConfig(plates=rows)
    monkeypatch.setenv(section_cache.CACHE_ENV, str(tmp_path))
    assert section_cache.user_section_cache() == SectionCache(tmp_path / "sections")
    section_from_plates.cache_clear()
    before = section.FE_SOLVES
    config.build(0.2)
    section_from_plates.cache_clear()
    config.build(0.2)
    assert section.FE_SOLVES == before + 1 and len(list((tmp_path / "sections").glob("*.npz"))) == 1
    monkeypatch.setenv(section_cache.CACHE_ENV, "")
    assert section_cache.cache_folder() is None and section_cache.user_section_cache() is None
    section_from_plates.cache_clear()
    config.build(0.2)
    section_from_plates.cache_clear()
    assert section.FE_SOLVES == before + 2
