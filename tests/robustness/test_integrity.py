"""Issue item 3: checksums are verified on read. One byte changed in an attachment, a chunk or a
metadata record makes every reader refuse the log, naming the damaged record; cosim writes the
data section's checksum."""
from __future__ import annotations

import struct
import zlib
from pathlib import Path

import pytest
from _craft import attachment_offset, records
from _robust import cosim_cli
from mcap.reader import make_reader

from cosim.errors import LogError
from cosim.log import LogRecorder, iter_messages, open_log, read_log


def damaged_copy(log: Path, target: Path, offset: int, new: bytes) -> Path:
    raw = bytearray(log.read_bytes())
    raw[offset:offset + len(new)] = new
    target.write_bytes(bytes(raw))
    return target


def every_command_refuses(log: Path, folder: Path, *fragments: str) -> None:
    for args in (("info", str(log)), ("export", str(log), "--csv", str(folder / "o.csv")),
                 ("plot", str(log), "-o", str(folder / "o.png")),
                 ("replay", str(log), "--out", str(folder / "r.mcap"))):
        result = cosim_cli(*args, cwd=folder)
        assert result.returncode == 2, (args, result.stdout, result.stderr)
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in result.stderr, lines
        for fragment in fragments:
            assert fragment in lines[0], (fragment, lines[0])
    assert not any((folder / name).exists() for name in ("o.csv", "o.png", "r.mcap", "runs"))


def test_one_byte_of_the_embedded_scenario_changed_is_refused(profiled_log: Path, tmp_path: Path) -> None:
    start, size = attachment_offset(profiled_log, "scenario.toml")
    text = profiled_log.read_bytes()[start:start + size]
    at = text.index(b"m_v = 1000.0")
    crafted = damaged_copy(profiled_log, tmp_path / "altered.mcap", start + at, b"m_v = 1100.0")
    assert b"m_v = 1100.0" in crafted.read_bytes()
    every_command_refuses(crafted, tmp_path, "corrupt MCAP file", "the checksum of attachment 'scenario.toml'",
                          "changed after it was written")


def test_a_changed_byte_in_a_chunk_names_the_chunk(profiled_log: Path, tmp_path: Path) -> None:
    with open(profiled_log, "rb") as fh:
        chunk = make_reader(fh).get_summary().chunk_indexes[-1]
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    raw = profiled_log.read_bytes()
    crafted = damaged_copy(profiled_log, tmp_path / "chunk.mcap", middle, bytes([raw[middle] ^ 0x01]))
    with pytest.raises(LogError, match=rf"chunk \d+ \(offset {chunk.chunk_start_offset}, messages at t = "):
        open_log(crafted)
    every_command_refuses(crafted, tmp_path, "corrupt MCAP file", f"offset {chunk.chunk_start_offset}")


def test_a_record_without_its_own_checksum_is_covered_by_the_data_sections(profiled_log: Path,
                                                                            tmp_path: Path) -> None:
    """The metadata record has no checksum of its own; the data section's catches a change in it."""
    opcode, offset, length = next(r for r in records(profiled_log) if r[0] == 0x0C)  # the "cosim" metadata
    raw = profiled_log.read_bytes()
    at = raw.index(b"profiled", offset, offset + 9 + length)  # the scenario's name in it
    crafted = damaged_copy(profiled_log, tmp_path / "meta.mcap", at, b"P")
    with pytest.raises(LogError, match="the checksum of the data section does not match"):
        open_log(crafted)


def test_cosim_writes_the_data_section_checksum(profiled_log: Path) -> None:
    raw = profiled_log.read_bytes()
    _, offset, length = next(r for r in records(profiled_log) if r[0] == 0x0F)  # DataEnd
    (crc,) = struct.unpack_from("<I", raw, offset + 9)
    assert length == 4 and crc == zlib.crc32(raw[:offset])  # every byte before DataEnd, the magic included


def test_a_truncated_log_is_still_read_and_its_chunks_still_checked(tmp_path: Path) -> None:
    log = tmp_path / "small-chunks.mcap"
    with LogRecorder(log, ["a"], chunk_size=4096) as rec:
        for k in range(3000):
            rec.write("/cosim/sensors", k * 0.01, {"t": k * 0.01, "a": 1e-3 * k})
    raw = log.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(raw[: len(raw) * 2 // 3])
    overview = open_log(cut)
    assert overview.truncated and 1000 < overview.counts["/cosim/sensors"] < 3000
    assert len(list(iter_messages(cut, ["/cosim/sensors"]))) == overview.counts["/cosim/sensors"]
    with open(log, "rb") as fh:
        chunk = make_reader(fh).get_summary().chunk_indexes[0]
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    damaged = damaged_copy(cut, tmp_path / "cut-damaged.mcap", middle, bytes([raw[middle] ^ 0x01]))
    with pytest.raises(LogError, match=f"chunk 1 \\(offset {chunk.chunk_start_offset}"):
        read_log(damaged)
