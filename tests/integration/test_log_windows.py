"""Long logs stay usable (issue 12): windows of time read only the chunks that overlap them, and
``cosim info`` reads a finished log's summary instead of every chunk.

One real run, logged by cosim at every step (40 s, 30 chunks of the usual 256 kB, all four exported
topics throughout: a slow car stays on the rough deck and lifts off again and again). The references
are computed independently: the whole export of the same log filtered by time, and the chunk index
as the ``mcap`` package reads it. Crafted files are that log with a few bytes changed.
"""
from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from _cli import TWO_CARS, cosim_cli
from mcap.reader import make_reader

from cosim.errors import CosimError, LogError
from cosim.log import TOPIC_EVENTS, TOPIC_SENSORS, TOPIC_STATUS, TOPIC_VEHICLES
from cosim.log.reader import iter_messages, open_log, sensor_series
from cosim.log.records import ReadStats
from cosim.log.schemas import to_ns
from cosim.run.export import export_csv
from cosim.run.figures import sensor_history

# The two-car bridge, the car at 0.5 m/s (40 s on the class H deck), every 2 ms step logged.
SLOW = (TWO_CARS.replace('name = "two-cars"', 'name = "slow"').replace("speed = 25.0", "speed = 0.5")
        .replace("[solver]\ndt = 0.002", "[solver]\ndt = 0.002\nduration = 40.0\n[output]\nevery = 1"))

TOPICS = (TOPIC_SENSORS, TOPIC_VEHICLES, TOPIC_EVENTS, TOPIC_STATUS)
# (from, to): inside, at the start, open on either side, past both ends, a single sample, none at all.
WINDOWS = [(10.0, 12.5), (0.0, 0.5), (None, 3.0), (37.0, None), (-5.0, 0.0), (39.999, 1e9), (12.002, 12.002001),
           (20.0011, 20.0019)]


def window_args(start: float | None, end: float | None) -> list[str]:
    return [*(["--from", repr(start)] if start is not None else []), *(["--to", repr(end)] if end is not None else [])]


def inside(row: bytes, start: float | None, end: float | None) -> bool:
    """The reference rule: the row's log time (integer ns of its t) within the window, both ends included."""
    ns = to_ns(float(row.split(b",", 1)[0]))
    return (start is None or ns >= to_ns(start)) and (end is None or ns <= to_ns(end))


def one_line_error(result, *fragments: str) -> None:  # noqa: ANN001
    assert result.returncode == 2, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("cosim: error: ") and "Traceback" not in result.stderr, lines
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


@pytest.fixture(scope="module")
def slow_log(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("slow")
    (folder / "slow.toml").write_text(SLOW, encoding="utf-8")
    result = cosim_cli("run", "slow.toml", "--out", "slow.mcap", "--quiet", cwd=folder)
    assert result.returncode == 0, result.stderr
    return folder / "slow.mcap"


@pytest.fixture(scope="module")
def chunk_index(slow_log: Path) -> tuple[list, dict[str, int]]:
    """The chunk index and channel ids as the ``mcap`` package reads them (an independent reader)."""
    with open(slow_log, "rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    return summary.chunk_indexes, {c.topic: cid for cid, c in summary.channels.items()}


@pytest.fixture(scope="module")
def whole_exports(slow_log: Path) -> dict[str, list[bytes]]:
    """Each topic exported whole, as lines (bytes, with their line ends)."""
    out = {}
    for topic in TOPICS:
        csv = slow_log.parent / f"whole-{topic.rsplit('/', 1)[-1]}.csv"
        result = cosim_cli("export", str(slow_log), "--topic", topic, "--csv", str(csv), cwd=slow_log.parent)
        assert result.returncode == 0, result.stderr
        out[topic] = csv.read_bytes().splitlines(keepends=True)
    return out


def test_the_log_spans_many_chunks_with_every_topic_throughout(chunk_index) -> None:  # noqa: ANN001
    chunks, ids = chunk_index
    assert len(chunks) >= 20
    late = [c for c in chunks if c.message_start_time > 20e9]
    for topic in (TOPIC_SENSORS, TOPIC_VEHICLES, TOPIC_EVENTS):
        assert any(ids[topic] in c.message_index_offsets for c in late), topic


# --------------------------------------------------------------------------- export of a window


def test_a_window_exports_exactly_the_rows_of_the_whole_export_in_it(slow_log: Path, whole_exports, tmp_path: Path
                                                                    ) -> None:  # noqa: ANN001
    for topic in TOPICS:
        header, *rows = whole_exports[topic]
        for k, (start, end) in enumerate(WINDOWS):
            csv = tmp_path / f"{topic.rsplit('/', 1)[-1]}-{k}.csv"
            result = cosim_cli("export", str(slow_log), "--topic", topic, *window_args(start, end), "--csv", str(csv),
                               cwd=tmp_path)
            assert result.returncode == 0, (topic, start, end, result.stderr)
            expected = [row for row in rows if inside(row, start, end)]
            assert csv.read_bytes() == header + b"".join(expected), (topic, start, end)  # bit for bit
            assert f"Wrote {len(expected)} rows of {topic} from " in result.stdout
    # The windows do select: a few seconds of sensors, one sample, none between two samples.
    sensors = whole_exports[TOPIC_SENSORS][1:]
    assert len((tmp_path / "sensors-0.csv").read_bytes().splitlines()) == 1 + 1251  # 10 to 12.5 s every 2 ms
    assert len([r for r in sensors if inside(r, 12.002, 12.002001)]) == 1
    assert not [r for r in sensors if inside(r, 20.0011, 20.0019)]


def test_a_window_reads_only_the_chunks_that_overlap_it(slow_log: Path, chunk_index, tmp_path: Path
                                                        ) -> None:  # noqa: ANN001
    chunks, ids = chunk_index

    def overlapping(topic: str, start: float, end: float | None) -> list:
        """The reference: the mcap package's chunk index, chunks with this topic overlapping the window."""
        lo, hi = to_ns(start), (to_ns(end) if end is not None else 1 << 64)
        return [c for c in chunks if c.message_end_time >= lo and c.message_start_time <= hi
                and ids[topic] in c.message_index_offsets]

    for topic in (TOPIC_SENSORS, TOPIC_EVENTS):
        for start, end in [(10.0, 12.5), (0.0, 0.5), (37.0, None)]:
            stats = ReadStats()
            messages = list(iter_messages(slow_log, [topic], start, end, stats))
            assert stats.chunks == len(overlapping(topic, start, end)) and stats.messages == len(messages), \
                (topic, start, end)
    assert 0 < len(overlapping(TOPIC_SENSORS, 10.0, 12.5)) <= len(chunks) // 4  # 2.5 s of 40
    stats = ReadStats()
    rows, _ = export_csv(slow_log, tmp_path / "w.csv", start=10.0, end=12.5, stats=stats)
    # What export reads: the chunk of the final status (open_log's summary), then the window's chunks.
    assert stats.chunks == 1 + len(overlapping(TOPIC_SENSORS, 10.0, 12.5)) and stats.messages == rows == 1251
    stats = ReadStats()
    export_csv(slow_log, tmp_path / "all.csv", stats=stats)
    assert stats.chunks == 1 + len(chunks)  # without a window every chunk is read (and every checksum checked)


def test_a_window_of_a_log_cut_short_is_walked_and_decodes_only_its_messages(slow_log: Path, whole_exports,
                                                                             tmp_path: Path) -> None:  # noqa: ANN001
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(slow_log.read_bytes()[: slow_log.stat().st_size * 3 // 5])
    overview = open_log(cut, check="summary")  # no summary to read: every complete chunk is walked
    assert overview.truncated and overview.chunks == overview.chunks_read and 10.0 < overview.end_time < 30.0
    result = cosim_cli("export", str(cut), "--from", "5", "--to", "9.5", "--csv", "part.csv", cwd=tmp_path)
    assert result.returncode == 0 and "was cut short (truncated)" in result.stderr, result.stderr
    header, *rows = whole_exports[TOPIC_SENSORS]
    expected = [row for row in rows if inside(row, 5.0, 9.5)]
    assert (tmp_path / "part.csv").read_bytes() == header + b"".join(expected)
    stats = ReadStats()
    assert len(list(iter_messages(cut, [TOPIC_SENSORS], 5.0, 9.5, stats))) == len(expected) == 2251
    assert stats.chunks == overview.chunks and stats.messages == len(expected)  # decoded: the window's only
    end = overview.end_time
    one_line_error(cosim_cli("export", str(cut), "--from", "35", "--csv", "late.csv", cwd=tmp_path),
                   f"--from 35 s: after the end of the log (the log covers t = 0 to {end:g} s)")
    assert not (tmp_path / "late.csv").exists()


# --------------------------------------------------------------------------- plot of a window


def test_a_plot_of_a_window_draws_the_samples_in_it(slow_log: Path, tmp_path: Path) -> None:
    result = cosim_cli("plot", str(slow_log), "--sensor", "mid", "--from", "10", "--to", "12", "-o", "w.png",
                       cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("Wrote 1 sensor time history (mid) from t = 10 to 12 s to w.png")
    assert (tmp_path / "w.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    full_t, full = sensor_series(slow_log, ["mid", "mid_left_acc"])
    keep = (full_t >= 10.0) & (full_t <= 12.0)
    t, series = sensor_history(slow_log, ["mid"], 10.0, 12.0, start=10.0, end=12.0)  # as plot draws it
    assert np.array_equal(t, full_t[keep]) and np.array_equal(series["mid"], full["mid"][keep]) and len(t) == 1001
    # More samples than a plot draws: the min/max envelope of the window's bins, from the window's start.
    bins = 50
    t, series = sensor_history(slow_log, ["mid"], 10.0, 12.0, start=10.0, end=12.0, max_points=2 * bins)
    index = np.minimum(((full_t[keep] - 10.0) / (2.0 / bins)).astype(int), bins - 1)
    lo = [full["mid"][keep][index == b].min() for b in range(bins)]
    hi = [full["mid"][keep][index == b].max() for b in range(bins)]
    assert np.array_equal(series["mid"][0::2], lo) and np.array_equal(series["mid"][1::2], hi)
    assert np.allclose(t[0::2], 10.0 + (np.arange(bins) + 0.5) * 2.0 / bins)


# --------------------------------------------------------------------------- bad windows


@pytest.mark.parametrize(("window", "fragment"), [
    (["--from", "5", "--to", "5"], "--from 5 --to 5: an empty window; --to must be later than --from"),
    (["--from", "12", "--to", "2"], "--from 12 --to 2: an empty window"),
    (["--from", "40.5"], "--from 40.5 s: after the end of the log (the log covers t = 0 to 40 s)"),
    (["--to", "-0.5"], "--to -0.5 s: before the start of the log (the log covers t = 0 to 40 s)"),
    (["--from", "nan"], "--from nan: expected a finite time in s"),
    (["--from", "1", "--to", "inf"], "--to inf: expected a finite time in s"),
])
def test_bad_windows_are_one_line_errors_and_write_nothing(slow_log: Path, tmp_path: Path, window: list[str],
                                                           fragment: str) -> None:
    for args in (("export", str(slow_log), "--csv", "o.csv"), ("plot", str(slow_log), "-o", "o.png")):
        one_line_error(cosim_cli(*args, *window, cwd=tmp_path), fragment)
    assert not list(tmp_path.iterdir())


def test_a_plot_window_without_a_sample_is_one_line(slow_log: Path, tmp_path: Path) -> None:
    one_line_error(cosim_cli("plot", str(slow_log), "--from", "20.0011", "--to", "20.0019", "-o", "o.png",
                             cwd=tmp_path), "no sensor sample between t = 20.0011 and 20.0019 s")
    with pytest.raises(CosimError, match="empty window"):  # the Python API checks like the command line
        export_csv(slow_log, tmp_path / "o.csv", start=3.0, end=1.0)
    assert not list(tmp_path.iterdir())


# --------------------------------------------------------------------------- info


def test_info_reads_the_summary_and_one_chunk_and_verify_reads_them_all(slow_log: Path, chunk_index) -> None:
    chunks, _ = chunk_index
    fast_stats, full_stats = ReadStats(), ReadStats()
    fast = open_log(slow_log, check="file", stats=fast_stats)
    full = open_log(slow_log, check="full", stats=full_stats)
    assert fast_stats.chunks == 1 and full_stats.chunks == len(chunks)  # the last chunk: the final status
    assert (fast.chunks_read, fast.chunks, fast.data_checksum) == (1, len(chunks), True)
    summary = open_log(slow_log, check="summary")  # what export and plot read first: no pass over the file
    assert (summary.chunks_read, summary.data_checksum, summary.counts) == (1, None, full.counts)
    for name in ("counts", "start_time", "end_time", "final_status", "attachments", "metadata", "sensor_names",
                 "quantities", "library"):
        assert getattr(fast, name) == getattr(full, name), name
    assert full.final_status["state"] == "finished" and full.counts[TOPIC_SENSORS] == 20001
    result = cosim_cli("info", str(slow_log))
    assert result.returncode == 0, result.stderr
    assert (f"Checked: checksums of the file (every byte as written), the summary and the attachments; 1 of "
            f"{len(chunks)} chunks decompressed; counts from the summary (--verify: every chunk)") in result.stdout
    verified = cosim_cli("info", "--verify", str(slow_log))
    assert verified.returncode == 0, verified.stderr
    assert (f"Checked: all {len(chunks)} chunks decompressed and their checksums verified, and the file's (every "
            "byte as written), the summary's and the attachments'; counts from the messages (the summary agrees)"
            ) in verified.stdout
    assert verified.stdout.replace(verified.stdout.splitlines()[-1], "") == \
        result.stdout.replace(result.stdout.splitlines()[-1], "")  # the same overview either way


# --------------------------------------------------------------------------- damage and lies


def damaged_copy(log: Path, target: Path, changes: dict[int, bytes]) -> Path:
    raw = bytearray(log.read_bytes())
    for offset, new in changes.items():
        raw[offset:offset + len(new)] = new
    target.write_bytes(bytes(raw))
    return target


def with_summary_crc(path: Path) -> Path:
    """The footer's summary checksum computed again, so that a changed summary passes it."""
    raw = bytearray(path.read_bytes())
    footer = len(raw) - 8 - 29
    start = struct.unpack_from("<Q", raw, footer + 9)[0]
    struct.pack_into("<I", raw, footer + 25, zlib.crc32(bytes(raw[footer:footer + 25]), zlib.crc32(raw[start:footer])))
    path.write_bytes(bytes(raw))
    return path


def summary_chunk_index_offsets(path: Path) -> list[int]:
    """File offsets of the chunk index records in the summary, in order."""
    raw = path.read_bytes()
    footer = len(raw) - 8 - 29
    position = struct.unpack_from("<Q", raw, footer + 9)[0]
    found = []
    while position < footer:
        opcode, length = struct.unpack_from("<BQ", raw, position)
        if opcode == 0x08:
            found.append(position)
        position += 9 + length
    return found


def test_a_window_checks_the_chunks_it_reads_and_info_the_whole_file(slow_log: Path, chunk_index,
                                                                     tmp_path: Path) -> None:  # noqa: ANN001
    chunks, _ = chunk_index
    chunk = next(c for c in chunks if c.message_start_time > 30e9)
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    damaged = damaged_copy(slow_log, tmp_path / "damaged.mcap", {middle: bytes([slow_log.read_bytes()[middle] ^ 1])})
    # A window elsewhere does not read that chunk (the price of reading only the window) ...
    assert cosim_cli("export", str(damaged), "--to", "20", "--csv", "early.csv", cwd=tmp_path).returncode == 0
    # ... a window over it does, and every whole read and info find the change.
    when = f"messages at t = {chunk.message_start_time / 1e9:g} to"
    one_line_error(cosim_cli("export", str(damaged), "--from", "30", "--csv", "late.csv", cwd=tmp_path),
                   "corrupt MCAP file", f"(offset {chunk.chunk_start_offset}, {when}")
    one_line_error(cosim_cli("info", str(damaged), cwd=tmp_path), "the checksum of the data section does not match")
    one_line_error(cosim_cli("info", "--verify", str(damaged), cwd=tmp_path), f"offset {chunk.chunk_start_offset}")
    assert not (tmp_path / "late.csv").exists()


def test_a_summary_that_lies_about_a_chunk_is_refused(slow_log: Path, chunk_index, tmp_path: Path
                                                      ) -> None:  # noqa: ANN001
    chunks, _ = chunk_index
    k = 12
    index_at = summary_chunk_index_offsets(slow_log)[k]
    start = chunks[k].message_start_time
    assert struct.unpack_from("<Q", slow_log.read_bytes(), index_at + 9)[0] == start
    later = struct.pack("<Q", start + 1_000_000)
    # The summary alone changed (its checksum not recomputed): every reader of the summary refuses it.
    changed = damaged_copy(slow_log, tmp_path / "changed.mcap", {index_at + 9: later})
    one_line_error(cosim_cli("info", str(changed), cwd=tmp_path), "the checksum of the summary does not match")
    # Its checksum made to match: the chunk says otherwise when a window reads it, and --verify compares.
    lying = with_summary_crc(damaged_copy(slow_log, tmp_path / "lying.mcap", {index_at + 9: later}))
    window = ["--from", f"{start / 1e9 + 0.01!r}", "--to", f"{start / 1e9 + 0.02!r}"]
    one_line_error(cosim_cli("export", str(lying), *window, "--csv", "o.csv", cwd=tmp_path),
                   f"chunk {k + 1} (offset {chunks[k].chunk_start_offset}", "is not what the summary's index says")
    one_line_error(cosim_cli("info", "--verify", str(lying), cwd=tmp_path),
                   f"the summary's chunk index does not match the chunks (it lists {len(chunks)}, the file holds "
                   f"{len(chunks)}; they differ from chunk {k + 1} on)")
    # A malformed index record (its message index map one byte short), checksum made to match.
    malformed = with_summary_crc(damaged_copy(slow_log, tmp_path / "malformed.mcap",
                                              {index_at + 9 + 32: struct.pack("<I", 9)}))
    one_line_error(cosim_cli("info", str(malformed), cwd=tmp_path), "a malformed ChunkIndex record in the summary")
    # The chunk's own header changed too, consistently: its messages still give it away.
    header_at = chunks[k].chunk_start_offset + 9
    both = with_summary_crc(damaged_copy(slow_log, tmp_path / "both.mcap", {index_at + 9: later, header_at: later}))
    with pytest.raises(LogError, match=rf"chunk {k + 1} \(offset \d+, messages at t = [\d.]+ to [\d.]+ s\) holds "
                                       r"messages at t = [\d.]+ to"):
        list(iter_messages(both, [TOPIC_SENSORS], start / 1e9, start / 1e9 + 0.5))
    assert not (tmp_path / "o.csv").exists()


def test_a_log_rewritten_by_the_mcap_package_is_windowed_through_its_index(slow_log: Path, whole_exports,
                                                                           tmp_path: Path) -> None:  # noqa: ANN001
    """Another writer's summary and chunk index (smaller chunks, no file checksum) serve windows alike."""
    from mcap.writer import CompressionType, Writer

    other = tmp_path / "other.mcap"
    with open(slow_log, "rb") as source, open(other, "wb") as out:
        reader = make_reader(source)
        summary = reader.get_summary()
        writer = Writer(out, compression=CompressionType.ZSTD, chunk_size=64 * 1024)
        writer.start(profile="cosim", library="mcap")
        schemas = {sid: writer.register_schema(s.name, s.encoding, s.data) for sid, s in summary.schemas.items()}
        channels = {cid: writer.register_channel(c.topic, c.message_encoding, schemas[c.schema_id])
                    for cid, c in summary.channels.items()}
        for attachment in reader.iter_attachments():
            writer.add_attachment(attachment.create_time, attachment.log_time, attachment.name,
                                  attachment.media_type, attachment.data)
        for metadata in reader.iter_metadata():
            writer.add_metadata(metadata.name, metadata.metadata)
        for _, channel, message in reader.iter_messages(log_time_order=False):
            writer.add_message(channels[channel.id], message.log_time, message.data, message.publish_time,
                               message.sequence)
        writer.finish()
    stats = ReadStats()
    overview = open_log(other, check="file", stats=stats)
    assert overview.data_checksum is False and stats.chunks == 1 and overview.chunks > 60
    result = cosim_cli("info", str(other), cwd=tmp_path)
    assert "the others not read (this log has no file checksum: older cosim versions wrote none)" in result.stdout
    result = cosim_cli("export", str(other), "--from", "10", "--to", "12.5", "--csv", "w.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    header, *rows = whole_exports[TOPIC_SENSORS]
    assert (tmp_path / "w.csv").read_bytes() == header + b"".join(r for r in rows if inside(r, 10.0, 12.5))


def test_info_lists_the_sumo_vehicles_of_a_long_log_from_its_start_unless_verify(tmp_path: Path,
                                                                                 monkeypatch: pytest.MonkeyPatch
                                                                                 ) -> None:
    """The vehicles come from the "entered" events: all of them with --verify, those of the first
    ``EVENT_CHUNKS`` chunks without (lowered here so that 2 min of SUMO traffic count as long)."""
    from cosim.run import loginfo
    from cosim.run.scenario import load_scenario

    text = load_scenario("paper-bridge-traffic").text.replace("end = 600.0 ", "end = 120.0 ", 1)
    (tmp_path / "sumo.toml").write_text(text.replace('name = "paper-bridge-traffic"', 'name = "two-minutes"', 1))
    result = cosim_cli("run", "sumo.toml", "--out", "sumo.mcap", "--quiet", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    log = tmp_path / "sumo.mcap"
    full = cosim_cli("info", "--verify", str(log)).stdout
    whole = next(line for line in full.splitlines() if line.startswith("Vehicles (SUMO, "))
    assert cosim_cli("info", str(log)).stdout.count(whole) == 1  # a short log: every chunk within the budget
    vehicles = int(whole.split()[2])
    monkeypatch.setattr(loginfo, "EVENT_CHUNKS", 3)
    fast = cosim_cli("info", str(log)).stdout
    start = next(line for line in fast.splitlines() if line.startswith("Vehicles (SUMO, "))
    assert ", in its first " in start and " s (--verify: the whole log)): " in start, start
    assert 0 < int(start.split()[2]) < vehicles
    assert full.replace(whole, "").splitlines()[:-1] == fast.replace(start, "").splitlines()[:-1]  # all else alike
