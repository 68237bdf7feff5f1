"""A deck given by its modes (cosim.core.modal_deck): the contact interpolation of docs/theory.md §13 and its
measured errors, the deck's surface, sensors, and every check of the arrays (one line naming the source and
the array)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import LinearNDInterpolator
from scipy.spatial import Delaunay

from cosim.core.modal_deck import ModalDeck
from cosim.core.sensors import Sensor
from cosim.errors import ConfigError

L, B = 30.0, 10.0  # an analytic deck field's span and width, m
K1, K2 = np.pi / L, np.pi / (2 * B)


def field(x, y, t=(1.0, 0.0)):
    """w = sin(pi x / L) cos(pi y / 2B), its derivative along t and t^T H t."""
    w = np.sin(K1 * x) * np.cos(K2 * y)
    gx, gy = K1 * np.cos(K1 * x) * np.cos(K2 * y), -K2 * np.sin(K1 * x) * np.sin(K2 * y)
    hxx, hyy, hxy = -K1**2 * w, -K2**2 * w, -K1 * K2 * np.cos(K1 * x) * np.sin(K2 * y)
    return np.array([w, t[0] * gx + t[1] * gy, t[0] ** 2 * hxx + 2 * t[0] * t[1] * hxy + t[1] ** 2 * hyy])


def grid_points(nx, ny, length=L, width=B):
    x, y = np.meshgrid(np.linspace(0, length, nx + 1), np.linspace(-width / 2, width / 2, ny + 1), indexing="ij")
    return np.column_stack([x.ravel(), y.ravel()])


def relative_errors(deck, x, y, t):
    rows = deck.rows(x, y, t)[:, :, 0].T  # (3, q)
    exact = field(x, y, t)
    return np.max(np.abs(rows - exact), axis=1) / np.max(np.abs(exact), axis=1)


RNG = np.random.default_rng(7)
QX, QY = RNG.uniform(0, L, 1500), RNG.uniform(-B / 2, B / 2, 1500)
OBLIQUE = (np.cos(0.3), np.sin(0.3))


# ------------------------------------------------------------------------------------------ interpolation
def test_a_structured_grid_reproduces_a_bicubic_field_exactly():
    """The tensor product of not-a-knot splines reproduces cubics both ways: rows exact to round-off along any
    direction, on a non-uniform grid."""
    x = np.array([0.0, 1.5, 4.0, 5.0, 8.5, 12.0])
    y = np.array([-3.0, -1.0, 0.5, 3.0])
    pts = np.array([(a, b) for a in x for b in y])

    def cubic(px, py):
        return (px**3 - 4 * px**2 + px) * (0.2 * py**3 - py + 2)

    deck = ModalDeck(pts, [1.0], cubic(pts[:, 0], pts[:, 1])[None])
    qx, qy = RNG.uniform(0, 12, 300), RNG.uniform(-3, 3, 300)
    t = (0.6, 0.8)
    rows = deck.rows(qx, qy, t)[:, :, 0]
    gx = (3 * qx**2 - 8 * qx + 1) * (0.2 * qy**3 - qy + 2)
    gy = (qx**3 - 4 * qx**2 + qx) * (0.6 * qy**2 - 1)
    hxx = (6 * qx - 8) * (0.2 * qy**3 - qy + 2)
    hxy = (3 * qx**2 - 8 * qx + 1) * (0.6 * qy**2 - 1)
    hyy = (qx**3 - 4 * qx**2 + qx) * 1.2 * qy
    exact = np.column_stack([cubic(qx, qy), t[0] * gx + t[1] * gy,
                             t[0] ** 2 * hxx + 2 * t[0] * t[1] * hxy + t[1] ** 2 * hyy])
    assert np.max(np.abs(rows - exact)) <= 1e-10 * np.max(np.abs(exact))
    assert "structured grid of 6 x 4" in deck.interpolation


@pytest.mark.parametrize("slopes", [False, True], ids=["spline slopes", "given slopes"])
def test_a_structured_grid_converges_at_orders_4_3_2(slopes):
    """w, its slope and its curvature along an oblique direction converge at the orders of cubic
    interpolation (docs/theory.md §13.3): measured 4.06, 3.03, 2.05 from 64 to 128 cells along."""
    errors = []
    for nx in (16, 32, 64, 128):
        pts = grid_points(nx, nx // 3)
        w = field(pts[:, 0], pts[:, 1])
        deck = ModalDeck(pts, [1.0], w[0][None], phi_x=w[1][None] if slopes else None)
        errors.append(relative_errors(deck, QX, QY, OBLIQUE))
    rates = np.log2(np.array(errors[-2]) / np.array(errors[-1]))
    assert rates[0] > 3.7 and rates[1] > 2.7 and rates[2] > 1.8, rates
    assert np.all(errors[-1] < [1e-7, 1e-5, 3e-4]), errors[-1]


def perturbed_mesh(nx, seed=0):
    """The nodes of an unstructured mesh: a grid with its inner nodes moved by up to 30 % of the spacing."""
    h = L / nx
    pts = grid_points(nx, int(round(B / h)))
    inner = (pts[:, 0] > 0) & (pts[:, 0] < L) & (np.abs(pts[:, 1]) < B / 2)
    pts[inner] += np.random.default_rng(seed).uniform(-0.3 * h, 0.3 * h, (int(inner.sum()), 2))
    return pts


def test_scattered_points_are_fitted_by_a_least_squares_spline():
    """An unstructured mesh's nodes (docs/theory.md §13.4): at the mesh's own nodes and at its triangles'
    centroids (between nodes), against the exact field, and against the mesh's own linear (P1) shape
    functions. Measured on 80 x 27 cells (2268 nodes): w 9e-8 / 2e-7 of its peak, w_x 5e-6, w_xx 4e-4; P1
    between nodes: 1.1e-3."""
    errors = {}
    for nx in (40, 80):
        pts = perturbed_mesh(nx)
        deck = ModalDeck(pts, [1.0], field(pts[:, 0], pts[:, 1])[0][None])
        assert "least-squares bicubic spline" in deck.interpolation
        centroids = pts[Delaunay(pts).simplices].mean(axis=1)
        at_nodes = relative_errors(deck, pts[:, 0], pts[:, 1], (1.0, 0.0))
        between = relative_errors(deck, centroids[:, 0], centroids[:, 1], (1.0, 0.0))
        p1 = LinearNDInterpolator(pts, field(pts[:, 0], pts[:, 1])[0])(centroids)
        p1_error = np.max(np.abs(p1 - field(centroids[:, 0], centroids[:, 1])[0]))
        errors[nx] = (at_nodes, between, p1_error)
    at_nodes, between, p1_error = errors[80]
    assert np.all(at_nodes < [3e-7, 2e-5, 1e-3]), at_nodes
    assert np.all(between < [6e-7, 2e-5, 1e-3]), between
    assert between[0] < p1_error / 100  # far closer than the mesh's own linear interpolation
    rates = np.log2(errors[40][1] / errors[80][1])
    assert rates[0] > 3.0 and rates[1] > 2.0 and rates[2] > 1.5, rates


def test_the_network_frame_gives_the_bridge_frames_rows_where_the_deck_is():
    """The same deck rotated and moved into a network frame: rows at the moved points along the rotated
    direction are the bridge frame's (the grid is found along the deck's own axis)."""
    pts = grid_points(20, 6)
    w = field(pts[:, 0], pts[:, 1])[0][None]
    bridge = ModalDeck(pts, [1.0], w)
    angle, shift = 0.7, np.array([4521.3, -1207.9])
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    network = ModalDeck(pts @ rot.T + shift, [1.0], w, frame="network")
    assert "structured grid of 21 x 7" in network.interpolation
    q = np.column_stack([QX, QY])
    t = np.array(OBLIQUE)
    moved = q @ rot.T + shift
    expected = bridge.rows(q[:, 0], q[:, 1], t)
    got = network.rows(moved[:, 0], moved[:, 1], rot @ t)
    assert np.max(np.abs(got - expected), axis=(0, 2)) == pytest.approx(0.0, abs=1e-9 * np.abs(expected).max())
    assert np.array_equal(network.covers(moved[:, 0], moved[:, 1]), np.ones(len(q), dtype=bool))


def test_rows_along_x_are_the_default_and_slopes_need_a_unit_direction():
    pts = grid_points(10, 3)
    deck = ModalDeck(pts, [1.0], field(pts[:, 0], pts[:, 1])[0][None])
    assert np.array_equal(deck.rows(QX[:5], QY[:5]), deck.rows(QX[:5], QY[:5], (1.0, 0.0)))
    with pytest.raises(ConfigError, match="unit"):
        deck.rows(1.0, 0.0, (2.0, 0.0))


# ------------------------------------------------------------------------------------------------ surface
def l_shaped():
    """An L-shaped deck (concave): 2 m squares, 3 x 3 with the top right 2 x 2 missing... as triangles."""
    pts, tris, index = [], [], {}
    cells = [(i, j) for i in range(3) for j in range(3) if not (i >= 1 and j >= 1)]
    for i, j in cells:
        for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)):
            if (a, b) not in index:
                index[(a, b)] = len(pts)
                pts.append((2.0 * a, 2.0 * b))
        c = [index[(i, j)], index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]]
        tris += [(c[0], c[1], c[2]), (c[0], c[2], c[3])]
    return np.array(pts), np.array(tris)


def test_the_surface_is_the_triangles_when_given():
    pts, tris = l_shaped()
    w = (pts[:, 0] * pts[:, 1] + 1.0)[None]
    with_triangles = ModalDeck(pts, [1.0], w, triangles=tris)
    hull = ModalDeck(pts, [1.0], w)
    notch = (4.0, 4.0)  # inside the L's bounding box, off its surface
    assert not with_triangles.covers(*notch)[0]
    assert hull.covers(*notch)[0]  # scattered points without triangles: their convex hull
    assert np.all(with_triangles.rows(*notch) == 0.0)  # a wheel there rides on rigid ground
    edge = (1.0, 6.0)  # on the boundary: covered
    assert with_triangles.covers(*edge)[0] and with_triangles.covers(6.0, 1.0)[0]
    assert not with_triangles.covers(6.0 + 1e-6, 1.0)[0] and not with_triangles.covers(-1e-6, 1.0)[0]


def test_a_structured_grid_without_triangles_covers_its_rectangle():
    pts = grid_points(6, 2)
    deck = ModalDeck(pts, [1.0], field(pts[:, 0], pts[:, 1])[0][None])
    assert deck.surface is None
    assert list(deck.covers([0.0, L, L + 1e-3, 15.0, 15.0], [0.0, B / 2, 0.0, B / 2 + 1e-3, -B / 2])) == [
        True, True, False, False, True]


def test_many_triangles_are_found_in_constant_time():
    """A fine mesh's triangles bucketed once: each point is tested against a bucket's few triangles."""
    pts = perturbed_mesh(200, seed=3)
    tris = Delaunay(pts).simplices
    deck = ModalDeck(pts, [1.0], np.ones((1, len(pts))), triangles=tris)
    index = deck.surface
    assert index is not None
    per_bucket = np.diff(index.start)
    assert per_bucket.mean() < 10 and per_bucket.max() < 40  # measured 6.1 and 18
    inside = deck.covers(QX, QY)
    assert inside.all()


# ------------------------------------------------------------------------------------------- sensors etc.
def test_sensors_read_the_deck_point_or_the_given_modal_values():
    pts = grid_points(6, 2)
    w = np.stack([field(pts[:, 0], pts[:, 1])[0], 0.5 * field(pts[:, 0], pts[:, 1])[0]])
    deck = ModalDeck(pts, [1.0, 3.0], w, quantities={"bending_moment:mid": [2e6, -1e5]}, source="deck.npz")
    row = deck.sensor_row(Sensor("acc", 15.0, 1.0, "acceleration"))
    assert row == pytest.approx(deck.rows(15.0, 1.0)[0, 0])
    assert list(deck.sensor_row(Sensor("mid", 15.0, 0.0, "bending_moment"))) == [2e6, -1e5]
    with pytest.raises(ConfigError) as error:
        deck.sensor_row(Sensor("quarter", 7.5, 0.0, "bending_moment"))
    assert str(error.value).startswith("sensor quarter: ") and "`bending_moment:quarter`" in str(error.value)
    assert "deck.npz" in str(error.value)
    with pytest.raises(ConfigError, match="^sensor off: .* not on the deck's surface"):
        deck.sensor_row(Sensor("off", 15.0, B, "displacement"))


def test_select_keeps_the_lowest_modes():
    pts = grid_points(6, 2)
    w = np.ones((3, len(pts)))
    deck = ModalDeck(pts, [1.0, 2.0, 5.0], w, zeta=[0.01, 0.02, 0.03], quantities={"strain:a": [1.0, 2.0, 3.0]})
    assert deck.select() is deck
    two = deck.select(cutoff_hz=4.0)
    assert two.n_modes == 2 and list(two.zeta) == [0.01, 0.02] and list(two.quantities["strain:a"]) == [1.0, 2.0]
    assert deck.select(n_modes=1, cutoff_hz=4.0).n_modes == 1
    with pytest.raises(ConfigError, match="no mode"):
        deck.select(cutoff_hz=0.5)


def test_arrays_are_read_only():
    pts = grid_points(3, 1)
    deck = ModalDeck(pts, [1.0], np.ones((1, len(pts))))
    with pytest.raises(ValueError):
        deck.phi[0, 0] = 2.0


# --------------------------------------------------------------------------------------------- bad input
N = 12  # points of the small deck the bad inputs start from: a grid of 4 x 3


def good(**change):
    pts = grid_points(3, 2)  # 4 x 3 = 12 points
    args = dict(points=pts, f_hz=[1.0, 2.0], phi=np.ones((2, len(pts))), source="deck.npz")
    args.update(change)
    return args


def _phi_with(value):
    phi = np.ones((2, N))
    phi[1, 5] = value
    return phi


BAD = {
    "phi shape": (dict(phi=np.ones((2, 11))), "deck.npz: phi: expected shape (2, 12)"),
    "phi rows": (dict(phi=np.ones((3, 12))), "deck.npz: phi: expected shape (2, 12)"),
    "phi nan": (dict(phi=_phi_with(np.nan)), "deck.npz: phi: phi[1, 5] is nan"),
    "phi inf": (dict(phi=_phi_with(np.inf)), "deck.npz: phi: phi[1, 5] is inf"),
    "points shape": (dict(points=np.ones((12, 3))), "deck.npz: points: expected shape (any, 2)"),
    "points nan": (dict(points=np.where(np.eye(12, 2, dtype=bool), np.nan, grid_points(3, 2))),
                   "deck.npz: points: points[0, 0] is nan"),
    "duplicate points": (dict(points=np.vstack([grid_points(3, 2)[:11], [[0.0, -5.0]]])),
                         "deck.npz: points: points 0 and 11 coincide"),
    "f descending": (dict(f_hz=[2.0, 1.0]), "deck.npz: f_hz: f_hz[1] = 1 Hz is below f_hz[0] = 2 Hz"),
    "f zero": (dict(f_hz=[0.0, 1.0]), "deck.npz: f_hz: f_hz[0] = 0 Hz"),
    "f negative": (dict(f_hz=[-1.0, 1.0]), "deck.npz: f_hz: f_hz[0] = -1 Hz"),
    "f nan": (dict(f_hz=[1.0, np.nan]), "deck.npz: f_hz: f_hz[1] is nan"),
    "no modes": (dict(f_hz=[], phi=np.ones((0, 12))), "deck.npz: f_hz: a deck needs at least one mode"),
    "zeta range": (dict(zeta=[0.02, 2.0]), "deck.npz: zeta: zeta[1] = 2"),
    "zeta shape": (dict(zeta=[0.02]), "deck.npz: zeta: expected shape (2,)"),
    "not mass-normalised": (dict(modal_mass=[1.0, 2.5]),
                            "deck.npz: modal_mass: mode 2's shape is not mass-normalised: modal_mass[1] = 2.5"),
    "triangle index": (dict(triangles=[[0, 1, 12]]), "deck.npz: triangles: triangles[0, 2] = 12 is not a point"),
    "triangle negative": (dict(triangles=[[0, -1, 2]]), "deck.npz: triangles: triangles[0, 1] = -1"),
    "triangle flat": (dict(triangles=[[0, 1, 2]]), "deck.npz: triangles: triangle 0 (0, 1, 2) has no area"),
    "triangle floats": (dict(triangles=np.array([[0.0, 1.0, 3.0]])), "deck.npz: triangles: expected (k, 3) integer"),
    "slopes in network": (dict(frame="network", phi_x=np.ones((2, 12))), "deck.npz: phi_x: slopes are given along"),
    "minus without plus": (dict(phi_x_minus=np.ones((2, 12))), "deck.npz: phi_x_minus: the slopes from -x need phi_x"),
    "phi_x shape": (dict(phi_x=np.ones((2, 3))), "deck.npz: phi_x: expected shape (2, 12)"),
    "frame": (dict(frame="global"), "deck.npz: `frame` must be one of bridge, network"),
    "quantity name": (dict(quantities={"moment:mid": [1.0, 2.0]}), "deck.npz: moment:mid: a modal quantity is named"),
    "quantity shape": (dict(quantities={"strain:mid": [1.0]}), "deck.npz: strain:mid: expected shape (2,)"),
    "two points": (dict(points=grid_points(3, 2)[:2], phi=np.ones((2, 2))),
                   "deck.npz: points: a deck needs at least 3"),
    "collinear": (dict(points=np.column_stack([np.arange(12.0), np.zeros(12)])),
                  "deck.npz: points: the deck points lie on a line"),
}


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
def test_bad_arrays_are_one_line_naming_the_source_and_the_array(case):
    change, start = BAD[case]
    with pytest.raises(ConfigError) as error:
        deck = ModalDeck(**good(**change))
        deck.rows(1.0, 0.0)  # the interpolation is built on first use
    message = str(error.value)
    assert message.startswith(start), message
    assert "\n" not in message


def test_sizes_are_bounded_before_anything_is_built(monkeypatch):
    monkeypatch.setenv("COSIM_MAX_DECK_POINTS", "10")
    with pytest.raises(ConfigError, match=r"^deck.npz: points: 12 points is more than the limit of 10 points .* "
                                          "COSIM_MAX_DECK_POINTS"):
        ModalDeck(**good())
    monkeypatch.delenv("COSIM_MAX_DECK_POINTS")
    monkeypatch.setenv("COSIM_MAX_MODE_VALUES", "20")
    with pytest.raises(ConfigError, match=r"^deck.npz: phi: 24 values \(2 modes x 12 points\) is more than"):
        ModalDeck(**good())


def test_the_compiled_step_reads_a_curved_paths_slope_and_curvature():
    """On a deck given by its modes the compiled step's contact rows along a curved wheel path y(x) are
    d/dx and d2/dx2 of w(x, y(x)) (docs/theory.md §13.8): w_x + y' w_y and w_xx + 2 y' w_xy + y'^2 w_yy + y'' w_y.
    Reference: the closed form for a bicubic field on a parabolic path, which the grid reproduces exactly
    (round-off, 1e-10 of the largest value)."""
    from cosim.core import kernels
    from cosim.core.modal_bridge import ModalBridge
    from cosim.core.surface_contact import surface_rows

    x = np.array([0.0, 1.5, 4.0, 5.0, 8.5, 12.0])
    y = np.array([-3.0, -1.0, 0.5, 3.0])
    pts = np.array([(a, b) for a in x for b in y])

    def cubic(px, py):
        return (px**3 - 4 * px**2 + px) * (0.2 * py**3 - py + 2)

    deck = ModalBridge(ModalDeck(pts, [1.0], cubic(pts[:, 0], pts[:, 1])[None])).kernel_deck()
    c0, c1, c2 = -1.0, 0.3, -0.02
    qx = np.linspace(0.2, 11.7, 200)
    qy, slope, curv = c0 + c1 * qx + c2 * qx**2, c1 + 2 * c2 * qx, np.full_like(qx, 2 * c2)
    path = np.zeros((1, len(qx), 5))
    path[0, :, 0], path[0, :, 1], path[0, :, 2], path[0, :, 4] = qy, 1.0, slope, curv
    kin = kernels.Kinematics(qx[None], np.full((1, len(qx)), 10.0), np.zeros((1, len(qx))), qy,
                             np.zeros((1, len(qx))), np.zeros((1, len(qx))), path)
    elems, rv = np.zeros(len(qx), dtype=np.int64), np.zeros((len(qx), 3, 1))
    surface_rows(kin, 0, deck, elems, rv, np.empty((3, 4)), np.empty((3, 4)), np.empty((3, 4, 4)))
    gx = (3 * qx**2 - 8 * qx + 1) * (0.2 * qy**3 - qy + 2)
    gy = (qx**3 - 4 * qx**2 + qx) * (0.6 * qy**2 - 1)
    hxx = (6 * qx - 8) * (0.2 * qy**3 - qy + 2)
    hxy = (3 * qx**2 - 8 * qx + 1) * (0.6 * qy**2 - 1)
    hyy = (qx**3 - 4 * qx**2 + qx) * 1.2 * qy
    exact = np.column_stack([cubic(qx, qy), gx + slope * gy,
                             hxx + 2 * slope * hxy + slope**2 * hyy + curv * gy])
    assert np.all(elems == 0)
    assert np.max(np.abs(rv[:, :, 0] - exact)) <= 1e-10 * np.max(np.abs(exact))
    # The straight path (no path array) reads the rows along x at the wheel's y.
    straight = kin._replace(path=np.zeros((0, 0, 5)))
    surface_rows(straight, 0, deck, elems, rv, np.empty((3, 4)), np.empty((3, 4)), np.empty((3, 4, 4)))
    assert np.max(np.abs(rv[:, :, 0] - np.column_stack([cubic(qx, qy), gx, hxx]))) <= 1e-10 * np.max(np.abs(exact))
