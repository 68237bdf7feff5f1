"""Where and when a WIM record enters SUMO (``via = "sumo"``, cosim.sumo.records): the arithmetic of its route,
against values worked out by hand below, on a route with lanes of different speed limits and a junction's
internal lane (the bundled network, which the integration tests drive, has one limit and no internal lanes).

The route: lane ``A`` (a normal edge, 100 m, 10 m/s), ``:J`` (a junction's internal lane, 10 m, 5 m/s), ``B``
(the deck's edge, 50 m, 20 m/s); the deck's entry end 10 m into ``B`` (120 m along the route). SUMO's step is
0.05 s from SUMO time 0; a vehicle added with depart ``d`` stands at its departure position at ``d + 0.05``.
"""
from __future__ import annotations

from datetime import date
from pathlib import Path

import pytest

from cosim.core.loads import VehicleRecord
from cosim.sumo.records import MAX_SPEED, RecordFeed, RecordRoute, RecordsPlan, travel_time, vehicle_length

ROUTE = RecordRoute(lane=1, direction=1, deck_lane="B_0", lanes=("A_0", ":J_0_0", "B_0"),
                    lengths=(100.0, 10.0, 50.0), limits=(10.0, 5.0, 20.0), edges=("A", "B"),
                    edge_of=((0, 0), (-1, -1), (1, 0)), entry=120.0, entry_limit=20.0)
FEED = RecordFeed(RecordsPlan(Path("wim.castor"), "castor", (1, 0), 0.0, 1e9, (ROUTE,)), step=0.05, begin=0.0)
FRONT = 1.2


def test_travel_time_adds_each_lanes_stretch_at_its_own_speed() -> None:
    # 100 m at 10 m/s + 10 m at 5 m/s + 10 m at 20 m/s = 10 + 2 + 0.5 s
    assert travel_time(ROUTE, 0.0, 120.0, 1.0) == pytest.approx(12.5, abs=1e-12)
    # a speed factor of 2: 100/20 + 10/10 + 10/40
    assert travel_time(ROUTE, 0.0, 120.0, 2.0) == pytest.approx(6.25, abs=1e-12)
    # capped at MAX_SPEED (70 m/s): factor 10 gives 100, 50 and 200 m/s -> 70, 50, 70
    assert travel_time(ROUTE, 0.0, 120.0, 10.0) == pytest.approx(100 / MAX_SPEED + 10 / 50 + 10 / MAX_SPEED)


def test_start_for_walks_back_or_on_through_the_lanes() -> None:
    # 1 s before the entry: 10 m of B (0.5 s), then 0.5 s of :J at 5 m/s = 2.5 m -> 107.5 m
    assert ROUTE.start_for(120.0, 1.0, 1.0) == pytest.approx(107.5, abs=1e-12)
    assert ROUTE.start_for(120.0, 12.5, 1.0) == pytest.approx(0.0, abs=1e-9)  # the route's start
    assert ROUTE.start_for(120.0, 13.0, 1.0) is None  # before it
    assert ROUTE.start_for(120.0, -1.0, 1.0) == pytest.approx(140.0, abs=1e-12)  # 1 s past it, on B at 20 m/s
    assert ROUTE.start_for(120.0, -3.0, 1.0) is None  # past the route's end (160 m)


def test_a_record_departs_from_the_routes_start_on_the_step_grid() -> None:
    """A record at 100 s, first axle 1.2 m behind the bumper: the bumper must be at 121.2 m at 100 s; from the
    start that takes 12.5 + 1.2/20 = 12.56 s, so depart = 100 - 0.05 - 12.56 = 87.39 s, rounded up onto the grid:
    87.40 s; the bumper then starts 0.01 s later on its way: at 12.55 s before 121.2 m, 0.1 m into A."""
    depart, lane, position = FEED.departure(ROUTE, 100.0, 1.0, FRONT, now=0.0)
    assert depart == pytest.approx(87.40, abs=1e-9) and lane == 0
    assert position == pytest.approx(0.1, abs=1e-9)


def test_a_record_read_late_starts_nearer_and_never_on_a_junction_lane() -> None:
    """At SUMO time 95 s the same record departs now, 4.95 s before its bumper's target: 0.56 s on B, 2 s on :J,
    2.39 s on A at 10 m/s: 23.9 m before A's end (76.1 m into A). At 98 s it would start on :J (1.95 s before),
    where SUMO inserts no vehicle: a step later each time until it is on B, at 99.40 s, 0.55 s before: 11 m before
    121.2 m, 0.2 m into B."""
    depart, lane, position = FEED.departure(ROUTE, 100.0, 1.0, FRONT, now=95.0)
    assert depart == pytest.approx(95.0) and lane == 0 and position == pytest.approx(76.1, abs=1e-9)
    depart, lane, position = FEED.departure(ROUTE, 100.0, 1.0, FRONT, now=98.0)
    assert depart == pytest.approx(99.40, abs=1e-9) and lane == 2 and position == pytest.approx(0.2, abs=1e-9)


def test_a_vehicle_is_as_long_as_its_axles() -> None:
    """First axle 1.2 m behind the bumper (a quarter of a wheelbase under 4.8 m, at least 0.5 m), last 0.5 m
    before the rear, or the recorded length if longer."""
    def record(spacings: tuple[float, ...], length: float = 0.0) -> VehicleRecord:
        return VehicleRecord(time=0.0, lane=1, direction=1, local_lane=1, speed=20.0, gross_weight=1e5,
                             axle_loads=(5e4,) * (len(spacings) + 1), axle_spacings=spacings, length=length,
                             origin=date(2000, 1, 1))

    assert vehicle_length(record((3.3, 5.2, 1.3, 1.3))) == pytest.approx((1.2 + 11.1 + 0.5, 1.2))
    assert vehicle_length(record((2.6,))) == pytest.approx((0.65 + 2.6 + 0.5, 0.65))
    assert vehicle_length(record((1.0,))) == pytest.approx((0.5 + 1.0 + 0.5, 0.5))
    assert vehicle_length(record((3.3, 5.2), length=16.5)) == pytest.approx((16.5, 1.2))
