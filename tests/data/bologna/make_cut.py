"""Cut the test networks and demands out of the Bologna "Andrea Costa" scenario (see README.md).

Run from this folder with the full scenario's folder as the argument (it needs
SUMO's netconvert and tools, from the eclipse-sumo wheel)::

    python make_cut.py PATH/TO/sumo-scenarios/bologna/acosta

It writes ``west.*`` and ``east.*`` here: a network cut to a box around the
bridges (netconvert rebuilds the junctions at the box's edge), the routes of
the vehicles that cross the box (SUMO's cutRoutes.py; departure times moved to
when each vehicle enters the box), only those departing in the first
``DEPART_BEFORE`` seconds, gzipped without a time stamp so that the files are
reproducible.
"""
from __future__ import annotations

import gzip
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import sumo

HERE = Path(__file__).resolve().parent
#: name -> box (xmin, ymin, xmax, ymax) in the network's coordinates
BOXES = {
    "west": (640, 150, 820, 300),     # edges 39/40 and 41/42: one lane per direction, a junction at each end
    "east": (1490, 420, 1660, 630),   # edges 113/43[1]: three lanes per direction, traffic lights at both ends
}
DEPART_BEFORE = 400.0  # s


def main(source: Path) -> None:
    home = Path(sumo.SUMO_HOME)
    env = {**os.environ, "SUMO_HOME": str(home)}
    for name, box in BOXES.items():
        with tempfile.TemporaryDirectory() as tmp:
            net = Path(tmp) / f"{name}.net.xml"
            subprocess.run([str(home / "bin" / "netconvert"), "-s", str(source / "acosta_buslanes.net.xml"),
                            "--keep-edges.in-boundary", ",".join(map(str, box)), "-o", str(net),
                            "--output.street-names", "true"], check=True, env=env)
            routes = Path(tmp) / "routes.xml"
            stops = HERE / f"{name}.stops.add.xml"
            subprocess.run([sys.executable, str(home / "tools" / "route" / "cutRoutes.py"), str(net),
                            str(source / "acosta.rou.xml"), str(source / "acosta_busses.rou.xml"),
                            "--orig-net", str(source / "acosta_buslanes.net.xml"), "-o", str(routes),
                            "-a", str(source / "acosta_bus_stops.add.xml"), "--stops-output", str(stops)],
                           check=True, env=env)
            text = routes.read_text(encoding="utf-8")
            body = text[re.search(r"^<routes[ >]", text, flags=re.M).start():]
            kept = [v for v in re.findall(r"    <vehicle .*?</vehicle>\n", body, flags=re.S)
                    if float(re.search(r'depart="([0-9.]+)"', v).group(1)) < DEPART_BEFORE]
            head = body[:body.index(">") + 1]
            out = '<?xml version="1.0" encoding="UTF-8"?>\n' + head + "\n" + "".join(kept) + "</routes>\n"
            (HERE / f"{name}.rou.xml.gz").write_bytes(gzip.compress(out.encode(), mtime=0))
            net_text = net.read_text(encoding="utf-8")
            net_text = net_text[re.search(r"^<net[ >]", net_text, flags=re.M).start():]  # drop the header (paths, date)
            (HERE / f"{name}.net.xml.gz").write_bytes(
                gzip.compress(('<?xml version="1.0" encoding="UTF-8"?>\n' + net_text).encode(), mtime=0))
            stops_text = stops.read_text(encoding="utf-8")
            start = re.search(r"^<additional[ >]", stops_text, flags=re.M).start()
            stops.write_text('<?xml version="1.0" encoding="UTF-8"?>\n' + stops_text[start:], encoding="utf-8")
            print(f"{name}: {len(kept)} vehicles")


if __name__ == "__main__":
    main(Path(sys.argv[1]).resolve())
