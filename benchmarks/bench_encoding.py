"""The log's encoders side by side: CPU and size of an hour of the default run's fixed-layout topics.

Issue 27, item 1: cosim's topics in a binary encoding that Foxglove reads natively, chosen by CPU and size among
the protobuf runtime, Foxglove's SDK writer and a compiled encoder of cosim's own. This script writes one
simulated hour of

- ``/cosim/sensors``: the default scenario's six sensors at 100 Hz (360,000 samples), smooth signals with
  full-precision round-off in their low bits (as a solver's output has; constant or short-period data would
  compress far better than a run's);
- ``/cosim/vehicles``: two vehicles on the deck in every one of 360,000 messages (an upper bound: the default
  run has 0 to 3 on the deck, none most of the time)

to an MCAP file (zstd, 256 kB chunks, as cosim writes) with each candidate, and reports the process CPU time
(encoding and writing together, one process, one thread for cosim's own; the SDK's compiled writer may use a
thread of its own, counted too) and the file's size:

- ``json template (previous versions)``: what the versions before protobuf did, reproduced here: a bytes
  %-template per message shape filled with the shortest round-trip numbers of one ``orjson`` call per block,
  written by cosim's bulk writer (the baseline of the ratios);
- ``json``: one ``orjson.dumps`` per message and the ``mcap`` package's writer;
- ``protobuf runtime``: one message object per row, ``SerializeToString``, the ``mcap`` writer;
- ``protobuf runtime + SDK``: the same bytes written by Foxglove's SDK (``foxglove.open_mcap``, its compiled
  MCAP writer, ``Channel.log(bytes)`` per message);
- ``fixed template + SDK``: cosim's encoder (:class:`cosim.log.proto.FixedTemplate`, all rows at once with
  numpy) written by the SDK;
- ``fixed template (cosim)``: cosim's encoder and cosim's writer (:class:`cosim.log.LogRecorder`'s bulk path),
  what a run does.

Run: ``python benchmarks/bench_encoding.py [--hours 1] [--out benchmarks/results/encoding.md]``.
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from cosim.core.fields import VEHICLE_FIELDS  # noqa: E402
from cosim.log import LogRecorder, proto  # noqa: E402
from cosim.log.schemas import TOPIC_SENSORS, TOPIC_VEHICLES  # noqa: E402

SENSORS = ("node1", "node2", "node3", "node3_acc", "edge_right", "moment_mid")
RATE_HZ = 100
NUMBERS = [f.name for f in VEHICLE_FIELDS if f.json_type != "string"]
CHUNK = 256 * 1024


def sensor_rows(n: int, rng: np.random.Generator) -> np.ndarray:
    """(n, 1 + sensors): t and smooth signals of a run's magnitudes with random low bits."""
    t = np.arange(n) / RATE_HZ
    scale = np.array([1e-2, 1.5e-2, 1.3e-2, 0.8, 1.3e-2, 4e6])
    phase = rng.uniform(0, 2 * np.pi, len(SENSORS))
    signal = np.sin(2 * np.pi * 2.04 * t[:, None] + phase) * np.exp(-((t[:, None] % 37.0) / 11.0))
    values = scale * (signal + 1e-3 * rng.standard_normal((n, len(SENSORS))))
    return np.column_stack([t, values])


def vehicle_rows(n: int, rng: np.random.Generator) -> np.ndarray:
    """(n, 1 + 2 * fields): t and two vehicles' numbers."""
    t = np.arange(n) / RATE_HZ
    cols = [t]
    for k in range(2):
        x = (t * 25.0 + 20.0 * k) % 40.0
        cols += [x, np.full(n, 1.6 - 3.2 * k), np.full(n, 25.0) + 0.1 * rng.standard_normal(n),
                 0.05 * rng.standard_normal(n), 1e-3 * rng.standard_normal(n), 0.3 * rng.standard_normal(n),
                 9.81e4 * (1 + 0.05 * rng.standard_normal(n))]
    return np.column_stack(cols)


def _vehicle_dict(row: np.ndarray) -> dict:
    vehicles = []
    for k, vid in enumerate(("car.1", "truck.7#1")):
        numbers = row[1 + k * len(NUMBERS):1 + (k + 1) * len(NUMBERS)]
        vehicles.append({"id": vid, "model": "quarter-car", **dict(zip(NUMBERS, map(float, numbers)))})
    return {"t": float(row[0]), "vehicles": vehicles}


def _sensor_dict(row: np.ndarray) -> dict:
    return {"t": float(row[0]), **dict(zip(SENSORS, map(float, row[1:])))}


def _runtime_class(message: str) -> type:
    from google.protobuf import descriptor_pb2, message_factory

    data = proto.schema_data(message, SENSORS)
    files = list(descriptor_pb2.FileDescriptorSet.FromString(data).file)
    return message_factory.GetMessages(files)[message]


def _runtime_encoder(message: str) -> Callable[[np.ndarray], bytes]:
    cls = _runtime_class(message)
    if message == "cosim.SensorSample":
        fields = ("t", *proto.sensor_fields(SENSORS))
        return lambda row: cls(**dict(zip(fields, map(float, row)))).SerializeToString()

    def vehicles(row: np.ndarray) -> bytes:
        value = _vehicle_dict(row)
        return cls(t=value["t"], vehicles=value["vehicles"]).SerializeToString()

    return vehicles


def _template(message: str) -> proto.FixedTemplate:
    spec = proto.spec_of(message, SENSORS if message == "cosim.SensorSample" else ())
    if message == "cosim.SensorSample":
        return proto.FixedTemplate(spec, {"t": proto.Hole(0), **{n: proto.Hole(i + 1) for i, n in enumerate(SENSORS)}})
    holes = iter(range(1, 1 + 2 * len(NUMBERS)))
    vehicles = [{f.name: vid if f.name == "id" else "quarter-car" if f.name == "model" else proto.Hole(next(holes))
                 for f in VEHICLE_FIELDS} for vid in ("car.1", "truck.7#1")]
    return proto.FixedTemplate(spec, {"t": proto.Hole(0), "vehicles": vehicles})


def _mcap_writer(path: Path, topic: str, encoding: str, schema_name: str, schema_encoding: str, schema: bytes,
                 messages: Callable[[], list[tuple[int, bytes]] | object]) -> None:
    from mcap.writer import CompressionType, Writer

    with open(path, "wb") as fh:
        writer = Writer(fh, chunk_size=CHUNK, compression=CompressionType.ZSTD)
        writer.start(profile="bench", library="bench")
        sid = writer.register_schema(schema_name, schema_encoding, schema)
        cid = writer.register_channel(topic, encoding, sid)
        for seq, (ns, data) in enumerate(messages()):
            writer.add_message(cid, ns, data, ns, seq)
        writer.finish()


def _sdk_writer(path: Path, topic: str, schema_name: str, schema: bytes, messages) -> None:  # noqa: ANN001
    import foxglove
    from foxglove.mcap import MCAPCompression, MCAPWriteOptions

    context = foxglove.Context()
    options = MCAPWriteOptions(compression=MCAPCompression.Zstd, chunk_size=CHUNK)
    writer = foxglove.open_mcap(path, allow_overwrite=True, context=context, writer_options=options)
    channel = foxglove.Channel(topic, schema=foxglove.Schema(name=schema_name, encoding="protobuf", data=schema),
                               message_encoding="protobuf", context=context)
    log = channel.log
    for ns, data in messages():
        log(data, log_time=ns)
    writer.close()


def _ns(rows: np.ndarray) -> list[int]:
    return [round(t * 1e9) for t in rows[:, 0]]


def measure(name: str, run: Callable[[Path], None], folder: Path) -> tuple[str, float, int]:
    path = folder / f"{name.replace(' ', '-').replace('(', '').replace(')', '').replace('+', 'and')}.mcap"
    start = time.process_time()
    run(path)
    cpu = time.process_time() - start
    return name, cpu, path.stat().st_size


def candidates(topic: str, rows: np.ndarray) -> dict[str, Callable[[Path], None]]:
    import orjson

    message = proto.TOPIC_MESSAGES[topic]
    schema = proto.schema_data(message, SENSORS if topic == TOPIC_SENSORS else ())
    as_dict = _sensor_dict if topic == TOPIC_SENSORS else _vehicle_dict

    def json_messages():  # noqa: ANN202
        return ((ns, orjson.dumps(as_dict(row))) for ns, row in zip(_ns(rows), rows))

    def runtime_messages():  # noqa: ANN202
        encode = _runtime_encoder(message)
        return ((ns, encode(row)) for ns, row in zip(_ns(rows), rows))

    def template_messages():  # noqa: ANN202
        data, size = _template(message).render_bytes(rows)
        return ((ns, data[i * size:(i + 1) * size]) for i, ns in enumerate(_ns(rows)))

    def json_template_writer(path: Path) -> None:
        if topic == TOPIC_SENSORS:
            template = b'{"t":%s' + b"".join(b',"' + n.encode() + b'":%s' for n in SENSORS) + b"}"
        else:
            items = [b'{"id":"' + vid.encode() + b'","model":"quarter-car",' + b",".join(
                b'"' + f.encode() + b'":%s' for f in NUMBERS) + b"}" for vid in ("car.1", "truck.7#1")]
            template = b'{"t":%s,"vehicles":[' + b",".join(items) + b"]}"
        width = rows.shape[1]
        with LogRecorder(path, list(SENSORS), force=True, chunk_size=CHUNK) as rec:
            times = list(rows[:, 0])
            for start in range(0, len(rows), 4096):
                block = rows[start:start + 4096]
                text = orjson.dumps(np.ascontiguousarray(block), option=orjson.OPT_SERIALIZE_NUMPY)
                tokens = text.replace(b"[", b"").replace(b"]", b"").split(b",")
                rec.write_encoded(topic, times[start:start + 4096],
                                  [template % tuple(tokens[i:i + width]) for i in range(0, len(tokens), width)])

    def cosim_writer(path: Path) -> None:
        names = list(SENSORS)
        with LogRecorder(path, names, force=True, chunk_size=CHUNK) as rec:
            template = _template(message)
            times = list(rows[:, 0])
            for start in range(0, len(rows), 4096):  # blocks, as a run hands them over
                block = rows[start:start + 4096]
                rec.write_encoded(topic, times[start:start + 4096], template.render(block))

    return {
        "json template (previous versions)": json_template_writer,
        "json": lambda p: _mcap_writer(p, topic, "json", message, "jsonschema", b"{}", json_messages),
        "protobuf runtime": lambda p: _mcap_writer(p, topic, "protobuf", message, "protobuf", schema,
                                                   runtime_messages),
        "protobuf runtime + SDK": lambda p: _sdk_writer(p, topic, message, schema, runtime_messages),
        "fixed template + SDK": lambda p: _sdk_writer(p, topic, message, schema, template_messages),
        "fixed template (cosim)": cosim_writer,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=1.0, help="simulated hours of messages")
    parser.add_argument("--out", help="also write the report to this Markdown file")
    args = parser.parse_args()
    n = round(args.hours * 3600 * RATE_HZ)
    rng = np.random.default_rng(27)
    lines = [f"# Encoders: {args.hours:g} simulated hour(s) of messages, {n} per topic", "",
             f"python {sys.version.split()[0]}, {os.cpu_count()} CPUs; CPU = process time (encode + write + zstd)",
             "", "| topic | candidate | CPU s | file MB | CPU vs previous | size vs previous |",
             "|---|---|---:|---:|---:|---:|"]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for topic, rows in ((TOPIC_SENSORS, sensor_rows(n, rng)), (TOPIC_VEHICLES, vehicle_rows(n, rng))):
            results = [measure(name, run, folder) for name, run in candidates(topic, rows).items()]
            _, cpu0, size0 = results[0]
            for name, cpu, size in results:
                lines.append(f"| {topic} | {name} | {cpu:.2f} | {size / 1e6:.2f} | {cpu / cpu0:.2f} | "
                             f"{size / size0:.2f} |")
                print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    if args.out:
        Path(args.out).write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
