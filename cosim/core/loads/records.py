"""WIM records: one vehicle a line, in the formats BTLS reads and writes, streamed (docs/loads.md).

:func:`read_records` streams a file (plain or gzip) record by record in
constant memory, checking every line: its length (the number of fields), each
field a number, positive weights, the axle loads adding up to the gross weight
within the format's rounding, one spacing fewer than axles, a known direction,
time never going backwards. A bad line is one :class:`~cosim.errors.ConfigError`
naming the file and the line, what was expected and how to fix it.
:func:`survey` reads a whole file that way first (what a run does before it
writes anything). :func:`write_records` writes records in any of the formats.

Times count from midnight of the file's first day, by the calendar (BTLS's own
clock has 25-day months and 10-month years; the two agree within a month).
Lanes are numbered as BTLS numbers them (``Vehicle::getGlobalLane``):
direction 1's lanes first, by their number in the file, then direction 2's
from the far side: a file's direction 2 / lane ``k`` is lane ``N - k + 1`` of
``N`` lanes (with one lane each way, direction 2's lane is lane 2).
"""
from __future__ import annotations

import gzip
import math
import os
import tempfile
import zlib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from datetime import date, timedelta
from pathlib import Path
from typing import IO, BinaryIO

from cosim.errors import ConfigError

from ..limits import MAX_WIM_RECORDS
from .formats import FORMATS, Format

#: Characters a line may have (a MON record of 99 axles has 1040).
MAX_LINE = 4096
#: Two-digit years (CASTOR, BeDIT; and years below 100 in DITIS and MON, as BTLS's simulations write them)
#: from this one on are 19xx, below it 20xx.
CENTURY_PIVOT = 70


@dataclass(frozen=True)
class VehicleRecord:
    """One vehicle of a WIM file, in SI units (raw units per format in docs/loads.md#the-record-formats).

    Attributes:
        time: when its first axle reaches the deck's entry end, s from midnight of the file's first day
            (``origin``); raw: hundredths of a second (CASTOR, BeDIT, DITIS) or milliseconds (MON).
        lane: BTLS's lane number on the road, from 1: direction 1's lanes, then direction 2's from the far
            side (see :func:`btls_lane`).
        direction: 1 or 2 (zero-based in BeDIT and MON files, one-based in CASTOR and DITIS).
        local_lane: the lane within its direction as in the file, from 1.
        speed: m/s (raw dm/s; MON km/h).
        gross_weight: N (raw 100 kg, MON kg; 1 x 100 kg = 981 N, BTLS's 9.81 m/s^2).
        axle_loads: N, front axle first (raw as the gross weight).
        axle_spacings: m, each axle to the next: one fewer than the axles (raw dm; MON mm).
        length: vehicle length, m (raw dm; MON mm); 0 if not recorded.
        transverse: transverse location in the lane, m (raw dm; DITIS cm; MON mm); 0 if not recorded.
        track_widths: each axle's track width, m (DITIS only, raw cm); () in the other formats.
        head: the record's head (type) code, as in the file.
        axle_groups: number of axle groups (MON only); 0 in the other formats.
        trailing_spacing: MON's spacing field after the last axle, m (raw mm); 0 in the other formats.
        origin: the file's first day: ``time`` counts from its midnight.
        line: the record's line in its file (0 for a record not read from a file): with the file, its id.
    """

    time: float
    lane: int
    direction: int
    local_lane: int
    speed: float
    gross_weight: float
    axle_loads: tuple[float, ...]
    axle_spacings: tuple[float, ...]
    length: float = 0.0
    transverse: float = 0.0
    track_widths: tuple[float, ...] = ()
    head: int = 0
    axle_groups: int = 0
    trailing_spacing: float = 0.0
    origin: date = date(2000, 1, 1)
    line: int = 0

    @property
    def axle_count(self) -> int:
        return len(self.axle_loads)


@dataclass(frozen=True)
class RecordsSummary:
    """What :func:`survey` found in a whole file.

    Attributes:
        count: records; lanes_per_direction: the highest lane number of each direction (BTLS's lane count).
        origin: the first day; first, last: the first and last record's time, s from its midnight.
    """

    count: int
    lanes_per_direction: tuple[int, int]
    origin: date
    first: float
    last: float


def btls_lane(direction: int, local_lane: int, lanes_per_direction: tuple[int, int]) -> int:
    """BTLS's lane number on the road (``Vehicle::getGlobalLane``): direction 1's lane ``k`` is ``k``;
    direction 2's lane ``k`` is ``N - k + 1`` with ``N`` the lanes of both directions."""
    return local_lane if direction == 1 else sum(lanes_per_direction) - local_lane + 1


def record_format(name: str) -> Format:
    """The :class:`~cosim.core.loads.formats.Format` called ``name``, or a :class:`ConfigError`."""
    fmt = FORMATS.get(str(name).lower())
    if fmt is None:
        raise ConfigError(f"format: {name!r} is not a WIM record format; expected one of {', '.join(FORMATS)}")
    return fmt


def survey(path: str | Path, format: str, visit: Callable[[VehicleRecord], None] | None = None) -> RecordsSummary:
    """Read and check a whole file (every line, as :func:`read_records` does), in constant memory.

    Args:
        path, format: the file and its format.
        visit: called with every record as it is read, if given (one pass for the file's checks and a caller's:
            a run's lanes and window). Its ``lane`` is the file's lane within its direction: BTLS's numbers need
            the whole file's lane counts (:attr:`RecordsSummary.lanes_per_direction`, :func:`btls_lane`).

    Raises:
        ConfigError: the first bad line (naming the file and the line), an empty file, too many records.
    """
    path = Path(path)
    count, lanes, first, last, origin = 0, [0, 0], 0.0, 0.0, date(2000, 1, 1)
    for record in _parse(path, record_format(format), None):
        if visit is not None:
            visit(record)
        if count == 0:
            first, origin = record.time, record.origin
        count += 1
        last = record.time
        lanes[record.direction - 1] = max(lanes[record.direction - 1], record.local_lane)
    if count == 0:
        raise ConfigError(f"{path}: no records (the file is empty); give a file with at least one vehicle")
    return RecordsSummary(count, (lanes[0], lanes[1]), origin, first, last)


def read_records(path: str | Path, format: str,
                 lanes_per_direction: tuple[int, int] | None = None) -> Iterator[VehicleRecord]:
    """Stream a WIM file's records (plain or gzip, by its first bytes), checking each line.

    Args:
        path: the file.
        format: ``"castor"``, ``"bedit"``, ``"ditis"`` or ``"mon"``.
        lanes_per_direction: lanes of direction 1 and 2, for BTLS's lane numbering; None: the highest lane
            number of each direction in the file, as BTLS counts them (the file is then surveyed first,
            one more pass).

    Raises:
        ConfigError: a bad line, named by file and line, raised when the iteration reaches it.
    """
    path = Path(path)
    fmt = record_format(format)
    if lanes_per_direction is None:
        lanes_per_direction = survey(path, format).lanes_per_direction
    elif (len(lanes_per_direction) != 2 or any(not isinstance(n, int) or n < 0 for n in lanes_per_direction)
          or sum(lanes_per_direction) < 1):
        raise ConfigError(f"lanes_per_direction: expected two lane counts >= 0, not both 0 "
                          f"(got {lanes_per_direction!r})")
    return _parse(path, fmt, (int(lanes_per_direction[0]), int(lanes_per_direction[1])))


def _open(path: Path) -> gzip.GzipFile | BinaryIO:
    try:
        with open(path, "rb") as probe:
            magic = probe.read(2)
        return gzip.open(path, "rb") if magic == b"\x1f\x8b" else open(path, "rb")
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read it ({exc.strerror or exc})") from None


def _lines(path: Path) -> Iterator[tuple[int, str]]:
    """(line number, text without its end of line) of the non-blank lines, each bounded in length."""
    limit = MAX_WIM_RECORDS.value()
    number = records = 0
    with _open(path) as stream:
        while True:
            try:
                raw = stream.readline(MAX_LINE + 2)
            except (OSError, EOFError, zlib.error) as exc:
                raise ConfigError(f"{path}: line {number + 1}: the gzip data is corrupt or cut short ({exc}); "
                                  "give the whole file") from None
            if not raw:
                return
            number += 1
            text = raw.rstrip(b"\r\n")
            if len(text) > MAX_LINE:
                raise ConfigError(f"{path}: line {number}: longer than {MAX_LINE} characters; a WIM record is one "
                                  "vehicle a line (a MON record of 99 axles has 1040); is this a WIM file?")
            try:
                line = text.decode("ascii").rstrip()
            except UnicodeDecodeError:
                raise ConfigError(f"{path}: line {number}: not ASCII text; a WIM record is digits and spaces in "
                                  "fixed-width columns") from None
            if not line:
                continue  # BTLS skips empty lines
            records += 1
            if records > limit:
                MAX_WIM_RECORDS.check(records, f"{path}: line {number}")
            yield number, line


class _Line:
    """One line being parsed: its fields by position, and errors that name the file and line."""

    def __init__(self, path: Path, number: int, text: str, fmt: Format) -> None:
        self.path, self.number, self.text, self.fmt = path, number, text, fmt

    def fail(self, message: str) -> ConfigError:
        return ConfigError(f"{self.path}: line {self.number}: {message}")

    def integer(self, start: int, width: int, field: str, required: bool = True) -> int:
        text = self.text[start:start + width].strip()
        if not text:
            if required:
                raise self.fail(f"{field} (columns {start + 1}-{start + width}) is blank; expected an integer "
                                f"({self.fmt.name.upper()} layout in docs/loads.md#the-record-formats)")
            return 0
        digits = text[1:] if text[0] == "-" else text
        if not digits.isdigit():
            raise self.fail(f"{field} (columns {start + 1}-{start + width}) is {text!r}; expected an integer "
                            f"({self.fmt.name.upper()} layout in docs/loads.md#the-record-formats)")
        value = int(text)
        if value < 0:
            raise self.fail(f"{field} is negative ({value}); expected a value >= 0")
        return value


_OPTIONAL = {"head", "length", "transverse", "groups"}
#: How messages name the header fields.
LABELS = {"gvw": "gross weight", "millis": "milliseconds", "transverse": "transverse location",
          "groups": "axle groups", "axles": "axle count"}


def _parse(path: Path, fmt: Format, lanes: tuple[int, int] | None) -> Iterator[VehicleRecord]:
    origin: date | None = None
    day_key: tuple[int, int, int] | None = None
    record_day = date(2000, 1, 1)
    previous, previous_line = -1, 0
    per_day = round(86400 / fmt.time_unit)
    for number, text in _lines(path):
        line = _Line(path, number, text, fmt)
        if len(text) < fmt.header_width:
            raise line.fail(f"{len(text)} characters, fewer than the {fmt.header_width} of a "
                            f"{fmt.name.upper()} record's vehicle fields; is the format right?")
        if "_" in text or "+" in text:  # int() would take "1_0" and "+1"; no field has them
            raise line.fail("has '_' or '+'; a WIM record is digits, spaces and minus signs in fixed-width columns")
        try:
            raw = {field: int(text[a:b]) for field, a, b in fmt.header_slices}
            if min(raw.values()) < 0:
                raise ValueError
        except ValueError:  # a blank optional field is 0; anything else is named by the careful path
            raw = {field: line.integer(a, b - a, LABELS.get(field, field), required=field not in _OPTIONAL)
                   for field, a, b in fmt.header_slices}
        key = (raw["year"], raw["month"], raw["day"])
        if key != day_key:
            day_key, record_day = key, _day(line, raw, fmt)
        if origin is None:
            origin = record_day
        ticks = _ticks(line, raw, fmt) + (record_day - origin).days * per_day
        if ticks < previous:
            raise line.fail(f"its time is {(previous - ticks) * fmt.time_unit:g} s before the previous record's "
                            f"(line {previous_line}); the records must be in time order: sort the file by time")
        previous, previous_line = ticks, number
        yield _record(line, raw, fmt, ticks, origin, lanes)


def _day(line: _Line, raw: dict[str, int], fmt: Format) -> date:
    year = raw["year"]
    if year < 100:  # two digits, or BTLS's simulated calendar (year 0, 1, ...) in a four-digit field
        year += 1900 if year >= CENTURY_PIVOT else 2000
    try:
        return date(year, raw["month"], raw["day"])
    except ValueError:
        raise line.fail(f"the date {raw['day']}/{raw['month']}/{raw['year']} (day/month/year) is not a date; "
                        "expected a real day") from None


def _ticks(line: _Line, raw: dict[str, int], fmt: Format) -> int:
    """Time of day in the format's unit (hundredths of a second or milliseconds)."""
    if raw["hour"] > 23 or raw["minute"] > 59:
        raise line.fail(f"the time {raw['hour']}:{raw['minute']:02d} is not a time of day; expected hours 0-23 "
                        "and minutes 0-59")
    minute = (raw["hour"] * 60 + raw["minute"]) * 60
    # BTLS rounds a time in the minute's last half-unit up without carrying (Vehicle::writeMONData and
    # writeCASTORData write 60000 ms, or 60 s and 0 hundredths) and reads it as the next minute's start
    if fmt.time_unit == 0.001:
        if raw["millis"] > 60000:
            raise line.fail(f"the milliseconds of the minute are {raw['millis']}; expected 0-60000")
        return minute * 1000 + raw["millis"]
    if raw["second"] * 100 + raw["hundredths"] > 6000:
        raise line.fail(f"the time within the minute is {raw['second']} s and {raw['hundredths']} hundredths; "
                        "expected 0-59 s and 0-99 hundredths (or 60 s and 0, the next minute's start)")
    return (minute + raw["second"]) * 100 + raw["hundredths"]


def _record(line: _Line, raw: dict[str, int], fmt: Format, ticks: int, origin: date,
            lanes: tuple[int, int] | None) -> VehicleRecord:
    n = raw["axles"]
    if not 1 <= n <= fmt.max_axles:
        raise line.fail(f"{n} axles; a {fmt.name.upper()} record has 1 to {fmt.max_axles}")
    _check_length(line, fmt, n)
    direction = raw["direction"] - fmt.direction_base + 1
    if direction not in (1, 2):
        first = fmt.direction_base
        raise line.fail(f"direction {raw['direction']}; {fmt.name.upper()} gives {first} or {first + 1}")
    local = raw["lane"]
    if local < 1:
        raise line.fail("lane 0; lanes are numbered from 1 within each direction")
    if lanes is not None and local > lanes[direction - 1]:
        raise line.fail(f"lane {local} of direction {direction}, but there are {lanes[direction - 1]} lane(s) in "
                        f"direction {direction}; give the right lane counts")
    if raw["speed"] <= 0:
        raise line.fail("speed 0; a vehicle's speed must be positive")
    if raw["gvw"] <= 0:
        raise line.fail("gross weight 0; a vehicle's weight must be positive")
    weights, spacings, tracks, trailing = _axles(line, fmt, n)
    tolerance = (n + 1) // 2  # n + 1 values each rounded to a unit: they may differ by up to (n + 1) / 2
    if abs(sum(weights) - raw["gvw"]) > tolerance:
        unit = "kg" if fmt.weight < 100.0 else "x 100 kg"
        raise line.fail(f"the axle loads add up to {sum(weights)} {unit} but the gross weight is {raw['gvw']} "
                        f"{unit}; with {n} axles rounded to 1 unit they may differ by at most {tolerance}: "
                        "correct the record or remove it")
    return VehicleRecord(
        time=ticks / round(1.0 / fmt.time_unit),
        lane=local if lanes is None else btls_lane(direction, local, lanes),
        direction=direction, local_lane=local,
        speed=raw["speed"] * fmt.speed,
        gross_weight=raw["gvw"] * fmt.weight,
        axle_loads=tuple(w * fmt.weight for w in weights),
        axle_spacings=tuple(s * fmt.spacing for s in spacings),
        length=raw["length"] * fmt.length,
        transverse=raw["transverse"] * fmt.transverse,
        track_widths=tuple(t * fmt.track for t in tracks),
        head=raw["head"], axle_groups=raw.get("groups", 0),
        trailing_spacing=trailing * fmt.spacing, origin=origin, line=line.number)


def _check_length(line: _Line, fmt: Format, n: int) -> None:
    """A line holds at least the record's axles (MON: each with its spacing) and at most every slot; slots
    past the record's axles must be zero (checked with the axles)."""
    have = len(line.text)
    spacing = 0 if fmt.spacing_after_last else dict(fmt.axle)["spacing"]
    least = fmt.header_width + n * fmt.axle_width - spacing
    most = fmt.line_width(fmt.max_axles)
    if have < least:
        each = " and spacing" if fmt.spacing_after_last else ""
        raise line.fail(f"{have} characters: the record says {n} axles but its axle fields end before the last of "
                        f"them ({least} characters needed: {fmt.header_width} + {fmt.axle_width} per axle for its "
                        f"weight{each}); the axle count and the axle fields disagree")
    if have > most:
        raise line.fail(f"{have} characters, more than the {most} of a {fmt.name.upper()} record "
                        f"({fmt.max_axles} axles at most); is the format right?")


def _axles(line: _Line, fmt: Format, n: int) -> tuple[list[int], list[int], list[int], int]:
    """Axle weights, the n - 1 spacings, track widths (DITIS) and MON's spacing after the last axle."""
    slots = fmt.max_axles if fmt.padded else max(n, -(-(len(line.text) - fmt.header_width) // fmt.axle_width))
    line.text = line.text.ljust(fmt.line_width(slots))
    try:
        return _axles_fast(line.text, fmt, n, slots)
    except ValueError:  # a blank, a non-number, a zero inside or a value past the axles: named carefully
        return _axles_careful(line, fmt, n, slots)


def _axles_fast(text: str, fmt: Format, n: int, slots: int) -> tuple[list[int], list[int], list[int], int]:
    """The axle fields of a well-formed line, or ValueError for anything :func:`_axles_careful` must name."""
    h, w = fmt.header_width, fmt.axle_width
    a, b = fmt.axle_offsets["weight"]
    weights = [int(text[h + i * w + a:h + i * w + b]) for i in range(n)]
    a, b = fmt.axle_offsets["spacing"]
    spacings = [int(text[h + i * w + a:h + i * w + b]) for i in range(n - 1)]
    if min(weights) <= 0 or (spacings and min(spacings) <= 0):
        raise ValueError
    trailing = int(text[h + (n - 1) * w + a:h + (n - 1) * w + b]) if fmt.spacing_after_last else 0
    tracks: list[int] = []
    if "track" in fmt.axle_offsets:
        c, d = fmt.axle_offsets["track"]
        tracks = [int(text[h + i * w + c:h + i * w + d]) for i in range(n)]
    # past the axles: the spacing after the last axle (if the format has none there) and every later slot
    rest = text[h + (n - 1) * w + a:] if not fmt.spacing_after_last else text[h + n * w:]
    if trailing < 0 or (tracks and min(tracks) < 0) or rest.strip(" 0"):
        raise ValueError
    return weights, spacings, tracks, trailing


def _axles_careful(line: _Line, fmt: Format, n: int, slots: int) -> tuple[list[int], list[int], list[int], int]:
    """:func:`_axles` field by field, naming the first bad one."""
    weights: list[int] = []
    spacings: list[int] = []
    tracks: list[int] = []
    trailing = 0
    at = fmt.header_width
    for i in range(slots):
        for field, width in fmt.axle:
            if field == "spacing" and i == slots - 1 and not fmt.spacing_after_last:
                continue
            used = i < n and not (field == "spacing" and i == n - 1)
            label = {"weight": f"axle {i + 1} weight", "track": f"axle {i + 1} track width",
                     "spacing": f"spacing {i + 1}-{i + 2}"}[field]
            if field == "spacing" and i == n - 1 and fmt.spacing_after_last:
                trailing = line.integer(at, width, "spacing after the last axle", required=False)
            elif used:
                value = line.integer(at, width, label, required=field != "track")
                if value == 0 and field != "track":
                    what = "weight" if field == "weight" else "spacing"
                    raise line.fail(f"{label} is 0, but the record says {n} axles: a zero {what} inside the "
                                    "vehicle; the axle count and the axle fields disagree")
                {"weight": weights, "spacing": spacings, "track": tracks}[field].append(value)
            elif i >= n or field == "spacing":
                if line.integer(at, width, label, required=False) != 0:
                    raise line.fail(f"{label} is given, but the record says {n} axles; the axle count and the "
                                    "axle fields disagree")
            at += width
    return weights, spacings, tracks, trailing


# --------------------------------------------------------------------------- writing

def write_records(path: str | Path, format: str, records: Iterable[VehicleRecord]) -> int:
    """Write records in a format BTLS reads (gzip if ``path`` ends in ``.gz``), replacing ``path`` only when
    all were written; returns how many.

    Values are rounded to the format's units (half away from zero). Times count from the first record's
    ``origin``. ``lane`` is not written (the file holds ``direction`` and ``local_lane``); head codes
    wider than the field keep their last digits, as BTLS writes them.

    Raises:
        ConfigError: a record that does not fit the format (naming the record by its position and the
            field), or times going backwards.
    """
    path = Path(path)
    fmt = record_format(format)
    folder = path.parent if str(path.parent) else Path(".")
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=folder)
    count = 0
    try:
        with os.fdopen(handle, "wb") as raw_out:
            out: IO[bytes] = (gzip.GzipFile(fileobj=raw_out, mode="wb", mtime=0)  # type: ignore[assignment]
                              if path.suffix == ".gz" else raw_out)
            origin, previous = None, -1
            for count, record in enumerate(records, start=1):
                origin = origin or record.origin
                ticks = _round((record.time + (record.origin - origin).days * 86400.0) / fmt.time_unit)
                if ticks < previous:
                    raise ConfigError(f"{path}: record {count}: its time is before the previous record's; "
                                      "write the records in time order")
                previous = ticks
                out.write(_format_record(fmt, record, origin, ticks, count, path).encode("ascii") + b"\n")
            if out is not raw_out:
                out.close()
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return count


def _round(value: float) -> int:
    return int(math.floor(abs(value) + 0.5)) * (1 if value >= 0 else -1)


def _format_record(fmt: Format, record: VehicleRecord, origin: date, ticks: int, index: int, path: Path) -> str:
    def fit(field: str, value: int, width: int) -> str:
        if field == "head":
            value %= 10 ** width
        if not 0 <= value < 10 ** width:
            raise ConfigError(f"{path}: record {index} (vehicle at {record.time:g} s): its {LABELS.get(field, field)} "
                              f"is {value} in "
                              f"{fmt.name.upper()}'s units, which does not fit {width} digits (0 to {10 ** width - 1})")
        return str(value).rjust(width)

    n = record.axle_count
    if not 1 <= n <= fmt.max_axles or len(record.axle_spacings) != n - 1:
        raise ConfigError(f"{path}: record {index}: {n} axles and {len(record.axle_spacings)} spacings; "
                          f"{fmt.name.upper()} takes 1 to {fmt.max_axles} axles and one spacing fewer")
    per_day = round(86400 / fmt.time_unit)
    day = origin + timedelta(days=ticks // per_day)
    of_day = ticks % per_day
    per_second = round(1.0 / fmt.time_unit)
    seconds, fraction = divmod(of_day, per_second)
    minutes, second = divmod(seconds, 60)
    hour, minute = divmod(minutes, 60)
    values = {
        "head": record.head, "day": day.day, "month": day.month,
        "year": day.year % 100 if fmt.year_digits == 2 else day.year, "hour": hour, "minute": minute,
        "second": second, "hundredths": fraction, "millis": second * 1000 + fraction,
        "speed": _round(record.speed / fmt.speed), "gvw": _round(record.gross_weight / fmt.weight),
        "length": _round(record.length / fmt.length), "axles": n,
        "direction": record.direction - 1 + fmt.direction_base, "lane": record.local_lane,
        "transverse": _round(record.transverse / fmt.transverse), "groups": record.axle_groups,
    }
    parts = [fit(field, values[field], width) for field, width in fmt.header]
    slots = fmt.max_axles if fmt.padded else n
    for i in range(slots):
        for field, width in fmt.axle:
            if field == "spacing" and i == slots - 1 and not fmt.spacing_after_last:
                continue
            if i >= n:
                value = 0
            elif field == "weight":
                value = _round(record.axle_loads[i] / fmt.weight)
            elif field == "track":
                value = _round(record.track_widths[i] / fmt.track) if i < len(record.track_widths) else 0
            else:
                value = (_round(record.axle_spacings[i] / fmt.spacing) if i < n - 1
                         else _round(record.trailing_spacing / fmt.spacing))
            parts.append(fit(f"axle {i + 1} {field}", value, width))
    return "".join(parts)
