"""SUMO input files: the one reader and editor of ``.sumocfg`` configs and the files they name.

A SUMO config is read as XML, never run: cosim needs the files it names to
embed them in a log (:func:`sumo_input_files`), to know the vTypes of the
demand, which ids are distributions and how many vehicles depart
(:func:`read_demand`, :func:`distribution_ids`), to run SUMO on a copy in a
scratch folder so that nothing is written next to the user's files
(:func:`write_sumo_set`), and to copy and edit a demand for a study run
(:func:`read_sumo_set` and the ``set_*`` edits).

The rules, the same for every caller:

- a file option (``net-file``, ``route-files``, ``additional-files``) lists
  its files separated by commas, each name stripped of surrounding white
  space, as SUMO 1.28 reads them (``"a.xml, b.xml c.xml"`` names ``a.xml`` and
  a file called ``b.xml c.xml``; SUMO separates with commas only);
- a relative name is relative to the config's folder;
- a file whose content starts with the gzip magic (``routes.rou.xml.gz``) is
  decompressed transparently, and an edited one is written back compressed;
- a config is read up to :data:`MAX_CONFIG_BYTES` and a gzipped file
  decompressed up to :data:`MAX_XML_BYTES` (a gzip bomb stops there);
- a problem is a :class:`~cosim.errors.ConfigError` of one line naming the file.
"""
from __future__ import annotations

import functools
import gzip
import io
import math
import xml.etree.ElementTree as ET
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cosim.errors import ConfigError
from cosim.sumo.library import HEAVY_VCLASSES  # not from vtypes: reading SUMO files needs no vehicle models

__all__ = [
    "DEMAND_OPTIONS",
    "FILE_OPTIONS",
    "Demand",
    "SumoConfig",
    "SumoSet",
    "VTypeEntry",
    "distribution_ids",
    "number_text",
    "read_config",
    "read_demand",
    "read_input",
    "read_sumo_set",
    "set_speed_limit",
    "set_truck_share",
    "set_vehicles_per_hour",
    "split_file_list",
    "sumo_input_files",
    "write_sumo_set",
]

#: The config options that name input files cosim reads, in the order they are listed.
FILE_OPTIONS = ("net-file", "route-files", "additional-files")
#: The options whose files hold the demand (flows, vTypes, distributions).
DEMAND_OPTIONS = ("route-files", "additional-files")
#: Largest ``.sumocfg`` read, bytes (a config is a few hundred bytes).
MAX_CONFIG_BYTES = 1 << 20
#: Largest decompressed content of a gzipped input file, bytes.
MAX_XML_BYTES = 1 << 30
GZIP_MAGIC = b"\x1f\x8b"


def number_text(value: float) -> str:
    """500.0 -> "500", 0.1 -> "0.1": the shortest text that reads back as the same number.

    cosim's one number formatter (SUMO files, study run ids, error messages): exact, never rounded, so two
    different values never print alike and a bound in a message never contradicts the value it reports."""
    value = float(value)
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)


# --------------------------------------------------------------------------- reading


def split_file_list(value: str) -> list[str]:
    """The file names of a config option's value: comma-separated, white space around each name dropped."""
    return [item.strip() for item in value.split(",") if item.strip()]


def decompressed(data: bytes, name: str) -> bytes:
    """``data`` itself, or its decompressed content if it is gzipped (at most :data:`MAX_XML_BYTES`).

    Raises:
        ConfigError: a broken or too large gzip stream.
    """
    if not data.startswith(GZIP_MAGIC):
        return data
    out = bytearray()
    try:
        # Member by member, as gzip.decompress does, but bounded.
        while data:
            inflater = zlib.decompressobj(wbits=16 + zlib.MAX_WBITS)
            out += inflater.decompress(data, MAX_XML_BYTES + 1 - len(out))
            if len(out) > MAX_XML_BYTES:
                raise ConfigError(f"{name}: more than {MAX_XML_BYTES} bytes once decompressed; not read")
            if not inflater.eof:
                raise ConfigError(f"{name}: not a readable gzip file (it ends early)")
            data = inflater.unused_data.lstrip(b"\0")
    except zlib.error as exc:
        raise ConfigError(f"{name}: not a readable gzip file ({exc})") from None
    return bytes(out)


def compressed_like(original: bytes, data: bytes) -> bytes:
    """``data`` gzipped (reproducibly: no time stamp) if ``original`` was, else ``data``."""
    return gzip.compress(data, mtime=0) if original.startswith(GZIP_MAGIC) else data


def read_input(path: Path) -> bytes:
    """The content of a SUMO input file, decompressed if it is gzipped.

    Raises:
        ConfigError: it cannot be read or decompressed.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read ({exc.strerror})") from None
    return decompressed(data, str(path))


def parse_xml(data: bytes, name: str) -> ET.Element:
    """The root element of XML ``data`` (gzipped or not), comments kept so that an edit keeps them.

    Raises:
        ConfigError: not well-formed XML (or a broken gzip stream).
    """
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    try:
        parser.feed(decompressed(data, name))
        return parser.close()
    except ET.ParseError as exc:
        raise ConfigError(f"{name}: not well-formed XML ({exc})") from None


def xml_bytes(root: ET.Element, note: str) -> bytes:
    """An XML document of ``root`` that starts with a comment saying what cosim changed."""
    body = ET.tostring(root, encoding="unicode")
    return f'<?xml version="1.0" encoding="UTF-8"?>\n<!-- {note} -->\n{body}\n'.encode()


@dataclass(frozen=True)
class SumoConfig:
    """A parsed ``.sumocfg``.

    Attributes:
        path: the config file.
        root: its XML (comments kept); :func:`read_sumo_set` rewrites the file options in it.
    """

    path: Path
    root: ET.Element

    def resolve(self, name: str) -> Path:
        """A file name of the config as a path: relative names are relative to the config's folder."""
        return self.path.parent / name  # an absolute name stays absolute

    def options(self, option: str) -> list[tuple[ET.Element, list[str]]]:
        """Every element of ``option`` (e.g. ``route-files``) with the file names of its value."""
        return [(element, split_file_list(element.get("value", ""))) for element in self.root.iter(option)]

    def files(self, options: tuple[str, ...] = FILE_OPTIONS) -> list[Path]:
        """The paths the config names under ``options``, in order, each once."""
        found: list[Path] = []
        for option in options:
            for _, names in self.options(option):
                for name in names:
                    path = self.resolve(name)
                    if path not in found:
                        found.append(path)
        return found


def read_config(path: str | Path) -> SumoConfig:
    """Parse a SUMO config (XML, at most :data:`MAX_CONFIG_BYTES`; never run).

    Raises:
        ConfigError: it cannot be read, is too large or is not well-formed XML.
    """
    path = Path(path)
    try:
        with path.open("rb") as handle:
            raw = handle.read(MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read the SUMO config ({exc.strerror})") from None
    if len(raw) > MAX_CONFIG_BYTES:
        raise ConfigError(f"{path}: more than {MAX_CONFIG_BYTES} bytes; not a SUMO config")
    return SumoConfig(path, parse_xml(raw, str(path)))


def sumo_input_files(config: str | Path) -> list[Path]:
    """The config, then the net, route and additional files it names that exist (each once).

    Raises:
        ConfigError: the config cannot be read or is not XML.
    """
    parsed = read_config(config)
    return [parsed.path, *(p for p in parsed.files() if p.is_file() and p != parsed.path)]


def distribution_ids(config: str | Path) -> set[str]:
    """Ids of the vTypeDistributions in the route and additional files of a config.

    Lenient: a config or file that cannot be read or parsed contributes nothing
    (SUMO, which loaded it, is the judge of its content).
    """
    try:
        parsed = read_config(config)
    except ConfigError:
        return set()
    found: set[str] = set()
    for path in parsed.files(DEMAND_OPTIONS):
        if not path.is_file():
            continue
        try:
            root = parse_xml(read_input(path), str(path))
        except ConfigError:
            continue
        found.update(dist.get("id", "") for dist in root.iter("vTypeDistribution"))
    return found


@dataclass(frozen=True)
class VTypeEntry:
    """A ``<vType>`` as the demand files write it.

    Attributes:
        id: its id; vclass: its ``vClass`` (None: not given, SUMO's "passenger");
        mass, length: its ``mass`` (kg) and ``length`` (m) attributes, or None when not given;
        params: its ``<param key value>`` entries; file: the file it is in.
    """

    id: str
    vclass: str | None
    mass: float | None
    length: float | None
    params: dict[str, str]
    file: str


@dataclass(frozen=True)
class Demand:
    """What the route and additional files of a config hold, as far as cosim needs it.

    Attributes:
        vtypes: vType id -> :class:`VTypeEntry` (distributions' members included).
        distributions: ids of the vTypeDistributions.
        untyped: some vehicle, trip or flow names no type (SUMO gives it ``DEFAULT_VEHTYPE``).
        vehicles: ``<vehicle>`` and ``<trip>`` elements; flows: ``<flow>`` elements.
        departures: (first, last) numeric ``depart`` of the vehicles and trips, s, or None.
    """

    vtypes: dict[str, VTypeEntry] = field(default_factory=dict)
    distributions: frozenset[str] = frozenset()
    untyped: bool = False
    vehicles: int = 0
    flows: int = 0
    departures: tuple[float, float] | None = None


def _float_attr(element: ET.Element, key: str, where: str) -> float | None:
    text = element.get(key)
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        raise ConfigError(f"{where}: `{key}` must be a number (got {text!r})") from None
    if not (math.isfinite(value) and value > 0):
        raise ConfigError(f"{where}: `{key}` must be a finite number > 0 (got {text!r})")
    return value


def _scan_demand(data: bytes, name: str) -> Demand:
    """One pass over a route or additional file (streamed: big city demands stay out of memory)."""
    vtypes: dict[str, VTypeEntry] = {}
    distributions: set[str] = set()
    untyped, vehicles, flows = False, 0, 0
    first, last = math.inf, -math.inf
    stack: list[str] = []
    try:
        for event, element in ET.iterparse(io.BytesIO(data), events=("start", "end")):
            tag = element.tag
            if event == "start":
                stack.append(tag)
                continue
            stack.pop()
            if tag == "vType":
                tid = element.get("id", "")
                where = f"{name}: vType {tid}"
                vtypes[tid] = VTypeEntry(
                    id=tid, vclass=element.get("vClass"), mass=_float_attr(element, "mass", where),
                    length=_float_attr(element, "length", where),
                    params={p.get("key", ""): p.get("value", "") for p in element.iter("param")}, file=name)
            elif tag == "vTypeDistribution":
                distributions.add(element.get("id", ""))
            elif tag in ("vehicle", "trip", "flow"):
                if not element.get("type") and "vTypeDistribution" not in stack:
                    untyped = True
                if tag == "flow":
                    flows += 1
                else:
                    vehicles += 1
                    try:
                        depart = float(element.get("depart", ""))
                    except ValueError:
                        depart = math.nan
                    if math.isfinite(depart):
                        first, last = min(first, depart), max(last, depart)
            if not stack or stack[-1] in ("routes", "additional"):
                element.clear()  # a top-level element is done with: free it
    except ET.ParseError as exc:
        raise ConfigError(f"{name}: not well-formed XML ({exc})") from None
    return Demand(vtypes, frozenset(distributions), untyped, vehicles, flows,
                  (first, last) if vehicles and first <= last else None)


@functools.lru_cache(maxsize=16)
def _demand_of_file(path: str, size: int, mtime_ns: int) -> Demand:
    return _scan_demand(read_input(Path(path)), str(path))


def read_demand(config: str | Path) -> Demand:
    """The vTypes, distributions and departures of a config's route and additional files (each once).

    Raises:
        ConfigError: the config or one of its demand files cannot be read or is not XML, or a vType's
            ``mass`` or ``length`` is not a number > 0.
    """
    parsed = read_config(config)
    vtypes: dict[str, VTypeEntry] = {}
    distributions: set[str] = set()
    untyped, vehicles, flows = False, 0, 0
    first, last = math.inf, -math.inf
    for path in parsed.files(DEMAND_OPTIONS):
        try:
            stat = path.stat()
        except OSError as exc:
            raise ConfigError(f"{parsed.path}: cannot read {path} ({exc.strerror})") from None
        part = _demand_of_file(str(path), stat.st_size, stat.st_mtime_ns)
        vtypes.update(part.vtypes)
        distributions |= part.distributions
        untyped = untyped or part.untyped
        vehicles += part.vehicles
        flows += part.flows
        if part.departures is not None:
            first, last = min(first, part.departures[0]), max(last, part.departures[1])
    return Demand(vtypes, frozenset(distributions), untyped, vehicles, flows,
                  (first, last) if first <= last else None)


# --------------------------------------------------------------------------- a config with its files, and edits


@dataclass(frozen=True)
class SumoSet:
    """A SUMO configuration and the files it names, flattened into one folder.

    Attributes:
        config: file name of the ``.sumocfg`` (a key of ``files``).
        files: file name -> content as read (gzipped files stay gzipped); the config's
            ``net-file``, ``route-files`` and ``additional-files`` are rewritten to these names.
        net: the network's file name; routes: route files; additional: additional files.
        label: how runs name it (a bundled level, or the config's file stem).
    """

    config: str
    files: dict[str, bytes]
    net: str
    routes: tuple[str, ...]
    additional: tuple[str, ...]
    label: str

    @property
    def demand_files(self) -> list[str]:
        """The route and additional files, each once."""
        return list(dict.fromkeys([*self.routes, *self.additional]))

    def with_files(self, files: dict[str, bytes]) -> SumoSet:
        return SumoSet(self.config, files, self.net, self.routes, self.additional, self.label)


def read_sumo_set(config: Path, label: str) -> SumoSet:
    """Read a ``.sumocfg`` and the network, route and additional files it names.

    Raises:
        ConfigError: the config or a file it names is missing or not XML, or two
            named files have the same file name.
    """
    parsed = read_config(config)
    files: dict[str, bytes] = {}
    named: dict[str, list[str]] = {}
    for option in FILE_OPTIONS:
        names: list[str] = []
        for element, items in parsed.options(option):
            rewritten = []
            for item in items:
                path = parsed.resolve(item)
                name = path.name
                try:
                    content = path.read_bytes()
                except OSError as exc:
                    raise ConfigError(f"{config}: {option}: cannot read {path} ({exc.strerror})") from None
                if name in files and files[name] != content:
                    raise ConfigError(f"{config}: {option}: two different files are named {name!r}; rename one")
                files[name] = content
                rewritten.append(name)
                names.append(name)
            element.set("value", ",".join(rewritten))
        named[option] = names
    if len(named["net-file"]) != 1:
        raise ConfigError(f"{config}: expected one net-file, got {len(named['net-file'])}")
    name = config.name if config.name.endswith(".sumocfg") else config.stem + ".sumocfg"
    files[name] = xml_bytes(parsed.root, f"{config.name}, its files flattened into this folder by cosim study")
    return SumoSet(config=name, files=files, net=named["net-file"][0], routes=tuple(named["route-files"]),
                   additional=tuple(named["additional-files"]), label=label)


def write_sumo_set(sumo: SumoSet, folder: Path) -> Path:
    """Write ``sumo``'s files into ``folder`` (flat, as named); returns the config written there."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, content in sumo.files.items():
        (folder / name).write_bytes(content)
    return folder / sumo.config


def set_vehicles_per_hour(sumo: SumoSet, rate: float) -> SumoSet:
    """The demand at ``rate`` vehicles per hour.

    With ``<flow>`` elements: every flow of the route and additional files gets
    ``vehsPerHour = rate`` (other rate keys removed), so each flow departs at
    that rate. A demand of individual vehicles and trips (a city's, with no
    flow) is scaled as a whole by SUMO's own ``scale`` option, set in the
    config: ``rate`` / (its vehicles per hour between the first and the last
    departure); SUMO then drops or duplicates vehicles at random, from the
    run's seed.

    Raises:
        ConfigError: neither a ``<flow>`` nor two departures at different times in the demand files, or
            one of them is not XML.
    """
    files = dict(sumo.files)
    count = 0
    for name in sumo.demand_files:
        root = parse_xml(files[name], name)
        flows = list(root.iter("flow"))
        if not flows:
            continue
        for flow in flows:
            for key in ("period", "probability", "number", "perHour"):
                flow.attrib.pop(key, None)
            flow.set("vehsPerHour", number_text(rate))
        count += len(flows)
        files[name] = compressed_like(files[name], xml_bytes(
            root, f"{name}: every flow at vehsPerHour = {number_text(rate)} (cosim study)"))
    if count:
        return sumo.with_files(files)
    vehicles, first, last = 0, math.inf, -math.inf
    for name in sumo.demand_files:
        part = _scan_demand(decompressed(files[name], name), name)
        vehicles += part.vehicles
        if part.departures is not None:
            first, last = min(first, part.departures[0]), max(last, part.departures[1])
    if vehicles < 2 or not last > first:
        raise ConfigError(f"{sumo.config}: vehicles_per_hour: no <flow> and no vehicles departing over a time span "
                          f"in its route or additional files ({', '.join(sumo.demand_files) or 'none'})")
    now = vehicles / ((last - first) / 3600.0)
    scale = rate / now
    root = parse_xml(files[sumo.config], sumo.config)
    for section in root:
        for old in [e for e in section if e.tag == "scale"]:
            section.remove(old)
    processing = next((e for e in root if e.tag == "processing"), None)
    if processing is None:
        processing = ET.SubElement(root, "processing")
    ET.SubElement(processing, "scale", value=repr(scale))
    files[sumo.config] = xml_bytes(
        root, f"{sumo.config}: the demand ({vehicles} vehicles, {now:.6g} per hour) scaled to "
              f"{number_text(rate)} per hour (cosim study)")
    return sumo.with_files(files)


def set_truck_share(sumo: SumoSet, share: float) -> SumoSet:
    """Rescale every ``vTypeDistribution``: heavy vTypes (:data:`HEAVY_VCLASSES`) to ``share``.

    Within each group the given probabilities keep their ratios. Both forms of
    distribution are handled: nested ``<vType probability=...>`` elements and
    ``vTypes="a b"`` with ``probabilities="..."``.

    Raises:
        ConfigError: no distribution, a share that needs a group the distribution lacks,
            or a demand file that is not XML.
    """
    files = dict(sumo.files)
    roots = {name: parse_xml(files[name], name) for name in sumo.demand_files}
    vclass: dict[str, str] = {}
    for root in roots.values():
        for vtype in root.iter("vType"):
            if vtype.get("id"):
                vclass[vtype.get("id", "")] = vtype.get("vClass", "passenger")
    changed: set[str] = set()
    found = 0
    for name, root in roots.items():
        for dist in root.iter("vTypeDistribution"):
            found += 1
            did = dist.get("id", "?")
            nested = [v for v in dist if v.tag == "vType"]
            if nested:
                ids = [v.get("id", "") for v in nested]
                probs = [float(v.get("probability", "1")) for v in nested]
            else:
                ids = (dist.get("vTypes") or "").split()
                text = (dist.get("probabilities") or "").split()
                probs = [float(p) for p in text] if text else [1.0] * len(ids)
                if len(probs) != len(ids):
                    raise ConfigError(f"{name}: vTypeDistribution {did}: vTypes and probabilities differ in length")
            heavy = [vclass.get(i, "passenger") in HEAVY_VCLASSES for i in ids]
            new = _rescale(probs, heavy, share, f"{name}: vTypeDistribution {did}")
            if nested:
                for v, p in zip(nested, new):
                    v.set("probability", number_text(p))
            else:
                dist.set("probabilities", " ".join(number_text(p) for p in new))
            changed.add(name)
    if not found:
        raise ConfigError(f"{sumo.config}: truck_share: no vTypeDistribution in its route or additional files "
                          "(the share rescales a distribution's probabilities)")
    for name in changed:
        files[name] = compressed_like(files[name], xml_bytes(
            roots[name], f"{name}: truck share {number_text(share)} (cosim study)"))
    return sumo.with_files(files)


def _rescale(probs: list[float], heavy: list[bool], share: float, where: str) -> list[float]:
    p = np.asarray(probs, dtype=float)
    h = np.asarray(heavy, dtype=bool)
    total_h, total_l = p[h].sum(), p[~h].sum()
    if share > 0 and total_h <= 0:
        raise ConfigError(f"{where}: truck_share = {number_text(share)} but it has no truck vType "
                          f"(vClass {', '.join(HEAVY_VCLASSES)}) with a probability > 0")
    if share < 1 and total_l <= 0:
        raise ConfigError(f"{where}: truck_share = {number_text(share)} but it has only truck vTypes")
    out = np.where(h, share * p / (total_h if total_h > 0 else 1.0),
                   (1.0 - share) * p / (total_l if total_l > 0 else 1.0))
    return [float(v) for v in out]


def set_speed_limit(sumo: SumoSet, speed: float) -> SumoSet:
    """Every lane of every non-internal edge of the network gets ``speed`` (m/s).

    Raises:
        ConfigError: the network is not XML or has no lanes.
    """
    files = dict(sumo.files)
    root = parse_xml(files[sumo.net], sumo.net)
    count = 0
    for edge in root.iter("edge"):
        if edge.get("function", "normal") != "normal":
            continue
        if edge.get("speed") is not None:
            edge.set("speed", number_text(speed))
        for lane in edge.iter("lane"):
            lane.set("speed", number_text(speed))
            count += 1
    if not count:
        raise ConfigError(f"{sumo.net}: speed_limit: the network has no lanes")
    files[sumo.net] = compressed_like(files[sumo.net], xml_bytes(
        root, f"{sumo.net}: every lane at speed {number_text(speed)} m/s (cosim study)"))
    return sumo.with_files(files)
