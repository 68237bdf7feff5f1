"""Where a ``frame = "network"`` modes file's deck lies on the bridge axis (docs/modal-decks.md#in-a-scenario).

The bridge runs along ``[traffic] axis`` (its direction only) or else along
the lanes of ``[traffic] edges``; x = 0 is the deck's first point along it.
The deck is moved into that bridge frame (a rotation and a shift:
:func:`cosim.core.modal_bridge.place_deck`), and SUMO is given the same axis.
"""
from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cosim.core.modal_bridge import ModalBridge, place_deck
from cosim.core.modal_deck import ModalDeck
from cosim.errors import ConfigError

from .config_base import fail
from .tables import TrafficConfig

#: An axis in network coordinates: (start, end), m.
Axis = tuple[tuple[float, float], tuple[float, float]]


def place_on_network(deck: ModalDeck, traffic: TrafficConfig, config: Path | None) -> tuple[ModalDeck, Axis]:
    """The network-frame ``deck`` in the bridge frame, and the axis (network m) from its x = 0 to its end.

    Args:
        deck: the modes file's deck, its points in network coordinates.
        traffic: ``[traffic]`` (its ``axis`` or ``edges`` give the direction).
        config: the SUMO config (its network locates the edges), or None.

    Raises:
        pydantic-reportable problems (:func:`cosim.run.config_base.fail`) naming the key: no direction given,
        an edge the network lacks.
    """
    if traffic.axis is not None:
        start, end = (np.asarray(p, dtype=float) for p in traffic.axis)
    elif traffic.edges and config is not None:
        from cosim.sumo.network import locate_bridge, net_path

        try:
            located = locate_bridge(net_path(config), traffic.edges).axis
        except ConfigError as exc:
            raise fail(str(exc), "traffic", "edges") from None
        start, end = np.asarray(located.start, dtype=float), np.asarray(located.end, dtype=float)
    else:
        raise fail('frame = "network" needs the bridge\'s direction: give [traffic] edges (the deck\'s edges) '
                   "or axis", "bridge", "frame")
    along = (end - start) / float(np.linalg.norm(end - start))
    x = (deck.points[:, 0] - start[0]) * along[0] + (deck.points[:, 1] - start[1]) * along[1]
    origin = start + float(x.min()) * along
    placed = place_deck(deck, (float(origin[0]), float(origin[1])), (float(along[0]), float(along[1])))
    far = origin + float(np.ptp(x)) * along
    return placed, ((float(origin[0]), float(origin[1])), (float(far[0]), float(far[1])))


def check_lanes_covered(bridge: ModalBridge, net: Path, lanes: Sequence[Any], axis: Any, where: str) -> None:
    """Every vehicle lane of ``[traffic] edges`` lies on the deck's surface over the deck's length (its centre
    line, the wheel path, sampled every metre), or one line names the lane and where it leaves the surface.

    Args:
        bridge: the deck given by its modes, in the bridge frame of ``axis``.
        net: the SUMO network; lanes: the edges' vehicle lanes (:class:`cosim.sumo.network.DeckLane`).
        axis: the bridge axis in network coordinates (:class:`cosim.sumo.network.BridgeAxis`).
        where: the scenario's source, for the message.
    """
    from cosim.sumo.network import polyline_samples, read_network

    network = read_network(net)
    for lane in lanes:
        x, y = axis.project(*polyline_samples(network.getLane(lane.id).getShape(), 1.0).T)
        inside = (x > 0.0) & (x < bridge.length)
        off = np.flatnonzero(inside & ~bridge.covers(x, y))
        if len(off):
            i = int(off[0])
            raise ConfigError(f"{where}: traffic.edges: lane {lane.id} leaves the deck's surface at x = {x[i]:.2f} m, "
                              f"y = {y[i]:.2f} m (bridge frame): the points of {bridge.source or 'the modes file'} "
                              "do not cover it; give points (or triangles) that cover every vehicle lane of the "
                              "edges")
