"""Whole runs on an OpenSeesPy model's modes (issue 26, item 5): moving forces and a quarter-car through
``from_opensees`` + :class:`~cosim.core.modal_bridge.ModalBridge` + :func:`~cosim.core.simulation.simulate`,
against the direct time integration of the same finite-element model.

The model (:func:`build`, this file's own): a simply supported 20 m x 10 m slab on five girders. A 0.20 m
slab of ShellMITC4 shells (E = 32 GPa, nu = 0.2, 2500 kg/m^3 plus 150 kg/m^2 of surfacing as mass) on five
0.4 x 1.0 m girders 2 m apart at y = -4 ... 4 m (elastic beam-columns, E = 36 GPa, consistent mass, their axes
0.6 m below the slab's mid-plane through rigid joint offsets), 1 m cantilevers to the edges at y = +-5 m, end
diaphragms (0.3 x 0.8 m), bearings under the girders at the slab's level. 10 shells along the span, 10
across (1 m): 121 nodes, 726 DOFs, first frequency 4.93 Hz. Its first 100 modes (to 275 Hz) are imported with
``from_opensees`` (OpenSees' default eigen solver; the slab's nodes are a grid, the slopes the nodes'
rotations). Damping: Rayleigh, 2 % at modes 1 and 4, the same alpha and beta on both sides (in the modal
route ``ExplicitDamping(alpha, beta)``: Phi^T (alpha M + beta K) Phi = diag(alpha + beta omega^2) exactly, so
the damping is the same for every kept mode).

The references:

- **OpenSees' own integration** (:func:`opensees_moving_forces`): ``Newmark 0.5 0.25`` (the average
  acceleration rule, cosim's), the same dt, each force a Path time series per node and DOF holding, at each
  step, the force's nodal loads at its position then (cosim also loads the deck at t_{n+1}). Two loadings:
  ``"cubic"``, the nodal forces and moments that do the force's work on cosim's contact interpolation along
  the wheel path (a node line: the Hermite cubic of the nodes' w and phi_x = -theta_y, docs/theory.md
  §13.3; along a girder that is the girder element's own cubic), so that the two sides load the model
  identically and their difference is the modal truncation alone; and ``"bilinear"``, the force shared by
  the shell's bilinear shape functions (MITC4's w), the FE model's own consistent load of a point force on the
  slab, whose difference from the first is the coarse mesh's, O(h^2).
- **A dense direct model of our own** (:class:`DenseNewmark`): OpenSees' assembled M and K (its ``GimmeMCK``
  integrator, ``printA``), C = alpha M + beta K, the average-acceleration rule on all 726 DOFs, and a
  quarter-car whose wheel follows the girder element's own cubic w(x) (wheel inertia, the convective terms
  2 v w_x' and v^2 w_xx, the suspension) written here in the full DOF space, eliminated by Sherman-Morrison
  with the bridge's effective matrix factorised once. It shares no code with cosim's coupled step; the same
  average-acceleration rule and the same contact rows along the girder make its all-mode limit cosim's, so
  what is left is, again, truncation. It is itself checked against OpenSees: the moving forces through it
  reproduce OpenSees' integration to round-off.

OpenSeesPy is a test oracle (the ``test`` extra installs it), never a dependency of cosim.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pytest
import scipy.sparse
import scipy.sparse.linalg

ops = pytest.importorskip("openseespy.opensees")

from cosim.bridges import from_opensees  # noqa: E402
from cosim.core.bridge import ExplicitDamping  # noqa: E402
from cosim.core.modal_bridge import ModalBridge  # noqa: E402
from cosim.core.roughness import RoadProfile  # noqa: E402
from cosim.core.sensors import Sensor  # noqa: E402
from cosim.core.simulation import SolverSettings, simulate  # noqa: E402
from cosim.core.traffic import ScriptedTraffic, ScriptedVehicle  # noqa: E402
from cosim.core.vehicles import MovingForce, QuarterCar  # noqa: E402

SPAN = 20.0  # m
GIRDERS_Y = (-4.0, -2.0, 0.0, 2.0, 4.0)  # m
EDGE = 5.0  # m: the deck is 10 m wide
NX = 10  # shells along the span (2 m); across: one per metre
N_MODES = 100
DT = 0.005  # s
G = 9.81  # m/s^2, cosim's default gravity
MASS = 10000.0  # kg: a 98.1 kN force
#: Two lanes right of the axis (y < 0), opposite directions: (y, speed, entry time, direction). The first runs
#: along a girder, the second on the slab midway between the two outer girders of that side.
LANES = ((-2.0, 20.0, 0.0, 1), (-3.0, 15.0, 0.2, -1))
DURATION = 1.7  # s: both crossings (the second ends at 1.53 s) and some free vibration
#: Where the responses are compared, mid-span: the loaded girder, the far girder, the deck edge.
OUTPUTS = {"loaded girder": (10.0, -2.0), "far girder": (10.0, 4.0), "deck edge": (10.0, -5.0)}


@dataclass
class Slab:
    """The built model: its grid of slab nodes (all on the deck) and its equations."""

    xs: np.ndarray
    ys: np.ndarray
    alpha: float = 0.0
    beta: float = 0.0
    equations: dict[int, list[int]] = field(default_factory=dict)

    def tag(self, i: int, j: int) -> int:
        return int(1 + i * len(self.ys) + j)

    def node_at(self, x: float, y: float) -> int:
        return self.tag(int(np.argmin(np.abs(self.xs - x))), int(np.argmin(np.abs(self.ys - y))))

    @property
    def deck_nodes(self) -> list[int]:
        return [self.tag(i, j) for i in range(len(self.xs)) for j in range(len(self.ys))]


def _rectangle(b: float, h: float) -> tuple[float, float, float, float]:
    """A, I about the horizontal axis, I about the vertical axis, J (St Venant) of a b x h rectangle."""
    long, short = max(b, h), min(b, h)
    j = long * short**3 * (1 / 3 - 0.21 * short / long * (1 - short**4 / (12 * long**4)))
    return b * h, b * h**3 / 12, h * b**3 / 12, j


def build(nx: int = NX) -> Slab:
    """The slab on five girders in OpenSeesPy (wipes the domain), in cosim's bridge frame (x along the span
    from the first support line, y to the left, z up)."""
    model = Slab(np.linspace(0.0, SPAN, nx + 1), np.linspace(-EDGE, EDGE, 11))
    xs, ys, tag = model.xs, model.ys, model.tag
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, x in enumerate(xs):
        for j, y in enumerate(ys):
            ops.node(tag(i, j), float(x), float(y), 0.0)
    ops.section("ElasticMembranePlateSection", 1, 32e9, 0.2, 0.2, 2500.0 + 150.0 / 0.2)
    element = 1
    for i in range(nx):
        for j in range(len(ys) - 1):
            ops.element("ShellMITC4", element, tag(i, j), tag(i + 1, j), tag(i + 1, j + 1), tag(i, j + 1), 1)
            element += 1
    lines = [int(np.argmin(np.abs(ys - g))) for g in GIRDERS_Y]
    a, i_y, i_z, j_t = _rectangle(0.4, 1.0)
    ops.geomTransf("Linear", 1, 0.0, 0.0, 1.0, "-jntOffset", 0.0, 0.0, -0.6, 0.0, 0.0, -0.6)
    for j in lines:
        for i in range(nx):
            ops.element("elasticBeamColumn", element, tag(i, j), tag(i + 1, j), a, 36e9, 15e9, j_t, i_y, i_z, 1,
                        "-mass", 2500.0 * a, "-cMass")
            element += 1
    a, i_y, i_z, j_t = _rectangle(0.3, 0.8)
    ops.geomTransf("Linear", 2, 0.0, 0.0, 1.0, "-jntOffset", 0.0, 0.0, -0.5, 0.0, 0.0, -0.5)
    for i in (0, nx):
        for j in range(lines[0], lines[-1]):
            ops.element("elasticBeamColumn", element, tag(i, j), tag(i, j + 1), a, 32e9, 13e9, j_t, i_y, i_z, 2,
                        "-mass", 2500.0 * a, "-cMass")
            element += 1
    for j in lines:
        lateral = 1 if j == lines[2] else 0
        ops.fix(tag(0, j), 1, lateral, 1, 0, 0, 0)
        ops.fix(tag(nx, j), 0, lateral, 1, 0, 0, 0)
    return model


def assembled(coefficients: tuple[float, float, float]) -> tuple[np.ndarray, dict[int, list[int]]]:
    """OpenSees' assembled m M + c C + k K (its GimmeMCK integrator; a dense system, plain numbering) and each
    node's equation numbers (-1: held). The analysis "fails" when the matrix is singular (M: the shells'
    rotations have no mass), after it has been assembled."""
    ops.wipeAnalysis()
    ops.system("FullGeneral")
    ops.numberer("Plain")
    ops.constraints("Plain")
    ops.integrator("GimmeMCK", *coefficients)
    ops.algorithm("Linear")
    ops.analysis("Transient")
    ops.analyze(1, 0.0)
    entries = np.array(ops.printA("-ret"))
    n = int(round(np.sqrt(len(entries))))
    equations = {int(t): [int(e) for e in ops.nodeDOFs(t)] for t in ops.getNodeTags()}
    ops.wipeAnalysis()
    return entries.reshape(n, n), equations


# ------------------------------------------------------------------------------------ the force's loads
def _cubic(u: float, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Hermite cubic's weights on (w_i, w_{i+1}, theta_i, theta_{i+1}) at u = (x - x_i)/h, and their first
    and second x-derivatives: w = H0 w_i + H1 w_i+1 + h G0 w_x,i + h G1 w_x,i+1 with w_x = -theta_y."""
    n0 = np.array([1 - 3 * u**2 + 2 * u**3, 3 * u**2 - 2 * u**3, -h * (u - 2 * u**2 + u**3), -h * (u**3 - u**2)])
    n1 = np.array([-6 * u + 6 * u**2, 6 * u - 6 * u**2, -h * (1 - 4 * u + 3 * u**2), -h * (3 * u**2 - 2 * u)]) / h
    n2 = np.array([-6 + 12 * u, 6 - 12 * u, -h * (-4 + 6 * u), -h * (6 * u - 2)]) / h**2
    return n0, n1, n2


def path_weights(model: Slab, x: float, y: float, kind: str) -> list[tuple[int, int, np.ndarray]]:
    """(node, DOF, weights n0, n1, n2) of a point on the node line nearest y at x: ``cubic`` (the Hermite cubic,
    w and theta_y) or ``bilinear`` (the shell's w: linear along a node line, no slopes)."""
    xs = model.xs
    h = float(xs[1] - xs[0])
    e = min(max(int(np.searchsorted(xs, x, side="right")) - 1, 0), len(xs) - 2)
    u = (x - xs[e]) / h
    j = int(np.argmin(np.abs(model.ys - y)))
    if kind == "bilinear":
        return [(model.tag(e, j), 3, np.array([1 - u, -1 / h, 0.0])),
                (model.tag(e + 1, j), 3, np.array([u, 1 / h, 0.0]))]
    n0, n1, n2 = _cubic(u, h)
    nodes = (model.tag(e, j), model.tag(e + 1, j), model.tag(e, j), model.tag(e + 1, j))
    return [(node, dof, np.array([n0[k], n1[k], n2[k]])) for k, (node, dof) in enumerate(zip(nodes, (3, 3, 5, 5)))]


def lane_positions(lane: tuple[float, float, float, int], times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x (m) of a scripted vehicle at each time and whether it is on the deck (cosim's ScriptedVehicle)."""
    _, speed, entry, direction = lane
    s = speed * (times - entry)
    x = s if direction > 0 else SPAN - s
    return x, (times >= entry) & (x >= 0.0) & (x <= SPAN)


def nodal_histories(model: Slab, kind: str, times: np.ndarray) -> dict[tuple[int, int], np.ndarray]:
    """(node, DOF) -> the load at each time (N, N m) of the forces of :data:`LANES`."""
    out: dict[tuple[int, int], np.ndarray] = {}
    for lane in LANES:
        x, on = lane_positions(lane, times)
        for k in np.flatnonzero(on):
            for node, dof, weights in path_weights(model, float(x[k]), lane[0], kind):
                out.setdefault((node, dof), np.zeros(len(times)))[k] += -MASS * G * weights[0]
    return out


_SERIES = [1]  # the next Path time series' tag (OpenSees keeps removed patterns' series)


def opensees_moving_forces(model: Slab, kind: str) -> np.ndarray:
    """OpenSees' Newmark (average acceleration) integration of the full model under the forces of
    :data:`LANES`: w at :data:`OUTPUTS`, m, (steps + 1, 3)."""
    steps = int(round(DURATION / DT))
    times = np.arange(steps + 1) * DT
    ops.wipeAnalysis()
    ops.reset()
    ops.setTime(0.0)
    for pattern in ops.getPatterns():
        ops.remove("loadPattern", pattern)
    series = _SERIES[0]
    for (node, dof), history in nodal_histories(model, kind, times).items():
        ops.timeSeries("Path", series, "-dt", DT, "-values", *history.tolist())
        ops.pattern("Plain", series, series)
        load = [0.0] * 6
        load[dof - 1] = 1.0
        ops.load(node, *load)
        series += 1
    _SERIES[0] = series
    ops.rayleigh(model.alpha, 0.0, model.beta, 0.0)  # beta on the initial stiffness: the same K, linear model
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.algorithm("Linear", "-factorOnce")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    nodes = [model.node_at(x, y) for x, y in OUTPUTS.values()]
    out = np.zeros((steps + 1, len(nodes)))
    for k in range(1, steps + 1):
        assert ops.analyze(1, DT) == 0, f"OpenSees failed at step {k}"
        out[k] = [ops.nodeDisp(n, 3) for n in nodes]
    return out


# ---------------------------------------------------------------------------------- the dense reference
class DenseHHT:
    """HHT-alpha on the full model, every DOF (hht = 0: Newmark's average acceleration rule, docs/theory.md
    (6.1)-(6.2)): M a + (1 + hht)(C v + K d)_{n+1} - hht (C v + K d)_n = (1 + hht) F_{n+1} - hht F_n with
    C = alpha M + beta K, beta_N = (1 - hht)^2 / 4, gamma_N = 1/2 - hht; the effective matrix
    M + (1 + hht)(gamma_N dt C + beta_N dt^2 K) factorised once (sparse LU)."""

    def __init__(self, model: Slab, mass: np.ndarray, stiffness: np.ndarray, dt: float, hht: float = 0.0):
        self.model, self.dt, self.hht, self.ca = model, dt, hht, 1.0 + hht
        self.k = scipy.sparse.csr_matrix(stiffness)
        self.c = scipy.sparse.csr_matrix(model.alpha * mass + model.beta * stiffness)
        self.b2, self.g1 = (1.0 - hht) ** 2 / 4 * dt * dt, (0.5 - hht) * dt
        effective = mass + self.ca * (self.g1 * self.c + self.b2 * self.k)
        self.lu = scipy.sparse.linalg.splu(scipy.sparse.csc_matrix(effective))
        n = len(mass)
        self.d, self.v, self.a = np.zeros(n), np.zeros(n), np.zeros(n)

    def predict(self) -> tuple[np.ndarray, np.ndarray]:
        """The predictors d~, v~ of (6.1)."""
        dt = self.dt
        return self.d + dt * self.v + (0.5 * dt * dt - self.b2) * self.a, self.v + (dt - self.g1) * self.a

    def internal(self, d_pred: np.ndarray, v_pred: np.ndarray) -> np.ndarray:
        """The right-hand side's part from the bridge's own forces: -(1 + hht)(C v~ + K d~) + hht (C v + K d)_n."""
        out = -self.ca * (self.c @ v_pred + self.k @ d_pred)
        if self.hht:
            out += self.hht * (self.c @ self.v + self.k @ self.d)
        return out

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        return self.lu.solve(rhs)

    def advance(self, acceleration: np.ndarray, d_pred: np.ndarray, v_pred: np.ndarray) -> None:
        self.a = acceleration
        self.d = d_pred + self.b2 * acceleration
        self.v = v_pred + self.g1 * acceleration

    def vector(self, weights: list[tuple[int, int, np.ndarray]], k: int) -> np.ndarray:
        """The DOF-space row of derivative k (0: w, 1: w_x, 2: w_xx) of a contact point's weights."""
        row = np.zeros(len(self.d))
        for node, dof, w in weights:
            eq = self.model.equations[node][dof - 1]
            if eq >= 0:  # -1: a held DOF (a bearing)
                row[eq] += w[k]
        return row

    def w(self, nodes: list[int]) -> list[float]:
        return [float(self.d[self.model.equations[n][2]]) for n in nodes]


def dense_moving_forces(model: Slab, mass: np.ndarray, stiffness: np.ndarray, kind: str) -> np.ndarray:
    """:func:`opensees_moving_forces` by :class:`DenseHHT` (average acceleration)."""
    steps = int(round(DURATION / DT))
    times = np.arange(steps + 1) * DT
    histories = nodal_histories(model, kind, times)
    solver = DenseHHT(model, mass, stiffness, DT)
    loads = np.zeros((steps + 1, len(mass)))
    for (node, dof), history in histories.items():
        eq = model.equations[node][dof - 1]
        if eq >= 0:  # -1: a held DOF (a bearing), whose load goes to the support
            loads[:, eq] += history
    nodes = [model.node_at(x, y) for x, y in OUTPUTS.values()]
    out = np.zeros((steps + 1, len(nodes)))
    for k in range(1, steps + 1):
        d_pred, v_pred = solver.predict()
        solver.advance(solver.solve(loads[k] + solver.internal(d_pred, v_pred)), d_pred, v_pred)
        out[k] = solver.w(nodes)
    return out


#: The quarter-car: a heavy axle (13.2 t), body at 2.5 Hz with 8 % damping, on the loaded girder's line. Its
#: speed puts no contact point on a node line across (the cubic's second derivative jumps there).
QC = QuarterCar(m_v=12000.0, m_w=1200.0, k_v=12000.0 * (2 * np.pi * 2.5) ** 2,
                c_v=2 * 0.08 * 12000.0 * 2 * np.pi * 2.5)
QC_LANE = (-2.0, 19.7, 0.0, 1)
QC_DURATION = 1.3
#: The road under it: waves r = A sin^2(pi (x - x0) / 5 m) of A = 5 mm from x0 = 0.2 m on (the car meets them at
#: 3.9 Hz, near the deck's first mode, 4.93 Hz; flat before x0, so that the car enters the deck level, as cosim
#: places a newcomer at the road's level where it appears), sampled every 5 mm: cosim interpolates the table
#: linearly, r and r_x alike, and so does :func:`road_at`.
_GRID = np.arange(4401) * 0.005 - 1.0
_PHASE = np.pi * np.maximum(_GRID - 0.2, 0.0) / 5.0
ROAD = RoadProfile(path_y=(QC_LANE[0],), x0=float(_GRID[0]), dx=0.005, r=0.005 * np.sin(_PHASE)[None, :] ** 2,
                   r_x=(0.005 * np.pi / 5.0 * np.sin(2 * _PHASE))[None, :], description="5 mm waves, 5 m long")


def road_at(x: float) -> tuple[float, float]:
    """r (m) and r_x at x of :data:`ROAD`'s table, interpolated linearly."""
    grid = ROAD.x0 + ROAD.dx * np.arange(ROAD.r.shape[1])
    return float(np.interp(x, grid, ROAD.r[0])), float(np.interp(x, grid, ROAD.r_x[0]))


def dense_quarter_car(model: Slab, mass: np.ndarray, stiffness: np.ndarray, hht: float) -> dict[str, np.ndarray]:
    """The quarter-car :data:`QC` crossing along :data:`QC_LANE` on the full model: docs/theory.md §5.5 written
    out here in the DOF space. The wheel follows the girder's cubic, u_w = n0 d, so u_w' = n0 d' + v n1 d and
    u_w'' = n0 d'' + 2 v n1 d' + v^2 n2 d; the road r(x) of :data:`ROAD` acts in the suspension,
    S = k_v (u_v - u_w - r) + c_v (u_v' - u_w' - v r_x); the body m_v u_v'' + S = 0; the deck
    M d'' + C d' + K d = n0^T (-W + S - m_w u_w''); the contact force P = W - S + m_w u_w''. Gravity is the
    static load W = (m_v + m_w) g, the vehicle's displacements are from its static equilibrium, at rest when it
    enters (docs/theory.md §5.3). HHT-alpha weights the non-inertial forces (the deck's, -W + S on the deck and
    S on the body) between t_n and t_{n+1}, inertia at t_{n+1}, the rows at x(t_{n+1}). The unknown
    accelerations (deck, body) are eliminated to one rank-one update of the factorised bridge matrix
    (Sherman-Morrison)."""
    q = QC
    steps = int(round(QC_DURATION / DT))
    times = np.arange(steps + 1) * DT
    x_all, on_all = lane_positions(QC_LANE, times)
    solver = DenseHHT(model, mass, stiffness, DT, hht)
    b2, g1, ca, dt = solver.b2, solver.g1, solver.ca, DT
    weight = (q.m_v + q.m_w) * G
    m_hat = q.k_v * b2 + q.c_v * g1
    d_body = q.m_v + ca * m_hat
    speed = QC_LANE[1]
    u, ud, udd, spring_n = 0.0, 0.0, 0.0, 0.0  # the body at rest in its static equilibrium; S_n
    force_n = np.zeros(len(mass))  # F_n: the vehicle's non-inertial force on the deck at the last step
    nodes = [model.node_at(x, y) for x, y in OUTPUTS.values()]
    out = {"w": np.zeros((steps + 1, len(nodes))), "P": np.full(steps + 1, np.nan),
           "body_acceleration": np.full(steps + 1, np.nan)}
    for k in range(1, steps + 1):
        d_pred, v_pred = solver.predict()
        u_pred, ud_pred = u + dt * ud + (0.5 * dt * dt - b2) * udd, ud + (dt - g1) * udd
        rhs = solver.internal(d_pred, v_pred) - hht * force_n
        if not on_all[k]:
            solver.advance(solver.solve(rhs), d_pred, v_pred)
            force_n = np.zeros(len(mass))
            out["w"][k] = solver.w(nodes)
            continue
        weights = path_weights(model, float(x_all[k]), QC_LANE[0], "cubic")
        n0, n1, n2 = (solver.vector(weights, i) for i in range(3))
        # u_w'' = r_w . a + h_w; S_{n+1} = s0 + m_hat b - s_r . a (a: the deck's accelerations, b: the body's)
        r_w = n0 + 2 * speed * g1 * n1 + b2 * speed**2 * n2
        h_w = 2 * speed * n1 @ v_pred + speed**2 * n2 @ d_pred
        s_r = m_hat * n0 + q.c_v * speed * b2 * n1
        r, r_x = road_at(float(x_all[k]))
        s0 = q.k_v * (u_pred - n0 @ d_pred - r) + q.c_v * (ud_pred - n0 @ v_pred - speed * n1 @ d_pred - speed * r_x)
        # body: m_v b + ca S_{n+1} - hht S_n = 0  ->  b = (ca (s_r . a - s0) + hht S_n) / d_body, and
        # ca S_{n+1} = ca m_v (s0 - s_r . a) / d_body + ca hht m_hat S_n / d_body
        p = q.m_w * r_w + ca * q.m_v / d_body * s_r  # (A + n0 p^T) a = f
        f = rhs + n0 * (-ca * weight + ca * (q.m_v * s0 + hht * m_hat * spring_n) / d_body - q.m_w * h_w)
        y0 = solver.solve(f)
        z0 = solver.solve(n0)
        acc = y0 - z0 * (p @ y0) / (1.0 + p @ z0)
        body = (ca * (s_r @ acc - s0) + hht * spring_n) / d_body
        spring = s0 + m_hat * body - s_r @ acc
        wheel = r_w @ acc + h_w
        solver.advance(acc, d_pred, v_pred)
        u, ud, udd, spring_n = u_pred + b2 * body, ud_pred + g1 * body, body, spring
        force_n = n0 * (-weight + spring)
        out["w"][k] = solver.w(nodes)
        out["P"][k] = weight - spring + q.m_w * wheel
        out["body_acceleration"][k] = body
    return out


# ------------------------------------------------------------------------------------------ the fixture
@dataclass
class Prepared:
    model: Slab
    bridge: ModalBridge
    mass: np.ndarray
    stiffness: np.ndarray
    opensees: dict[str, np.ndarray]  # OpenSees' integration under the moving forces, per loading


@pytest.fixture(scope="module")
def prepared() -> Any:
    """The model built, its modes imported, its matrices assembled and OpenSees' two integrations, once."""
    model = build()
    deck = from_opensees(model.deck_nodes, N_MODES)
    w1, w4 = 2 * np.pi * deck.f_hz[0], 2 * np.pi * deck.f_hz[3]
    model.beta = 2 * 0.02 / (w1 + w4)
    model.alpha = w1 * w4 * model.beta
    mass, model.equations = assembled((1.0, 0.0, 0.0))
    stiffness, equations = assembled((0.0, 0.0, 1.0))
    assert equations == model.equations
    opensees = {kind: opensees_moving_forces(model, kind) for kind in ("cubic", "bilinear")}
    yield Prepared(model, ModalBridge(deck, ExplicitDamping(model.alpha, model.beta)), mass, stiffness, opensees)
    ops.wipe()


SENSORS = [Sensor(name.replace(" ", "_"), x, y) for name, (x, y) in OUTPUTS.items()]


def cosim_moving_forces(bridge: ModalBridge, n_modes: int) -> np.ndarray:
    fleet = tuple(ScriptedVehicle(f"force-{k}", MovingForce(MASS), y, speed, entry_time=entry, direction=d)
                  for k, (y, speed, entry, d) in enumerate(LANES))
    result = simulate(bridge, ScriptedTraffic(fleet, bridge.length), DURATION, SolverSettings(dt=DT, modes=n_modes),
                      SENSORS)
    return np.column_stack([result.sensors[s.name] for s in SENSORS])


def relative_errors(got: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """The largest difference over the run at each output, as a share of the reference's peak there."""
    return np.max(np.abs(got - reference), axis=0) / np.max(np.abs(reference), axis=0)


def cosim_quarter_car(bridge: ModalBridge, n_modes: int, settings: SolverSettings) -> tuple[np.ndarray, dict]:
    """cosim's run of :data:`QC` on the imported modes: w at :data:`OUTPUTS` and the car's samples."""
    vehicle = ScriptedVehicle("qc", QC, QC_LANE[0], QC_LANE[1], entry_time=QC_LANE[2], direction=QC_LANE[3])
    result = simulate(bridge, ScriptedTraffic((vehicle,), bridge.length), QC_DURATION,
                      replace(settings, modes=n_modes), SENSORS, road=ROAD)
    return np.column_stack([result.sensors[s.name] for s in SENSORS]), result.vehicle("qc")


# ------------------------------------------------------------------------------------------------ tests
def test_the_dense_reference_is_opensees_own_integration(prepared):
    """The dense model of our own (OpenSees' assembled M and K, the average-acceleration rule in numpy) under
    the moving forces' nodal loads reproduces OpenSees' own integration to round-off (measured 4e-13 of the
    peak; tolerance 1e-9): its matrices, its damping and its rule are OpenSees', so it may stand in for OpenSees
    where OpenSees cannot go (a vehicle coupled to the deck)."""
    reference = prepared.opensees["cubic"]
    dense = dense_moving_forces(prepared.model, prepared.mass, prepared.stiffness, "cubic")
    assert np.all(relative_errors(dense, reference) <= 1e-9), relative_errors(dense, reference)


#: The modal truncation error of moving forces through the imported modes (:data:`LANES`): the largest
#: difference over the run from OpenSees' integration with the same loads ("cubic"), as a share of the direct
#: response's peak there, at the loaded girder, the far girder and the deck edge (mid-span). Measured:
#: 10 modes 1.55, 0.54, 1.14 %; 20 modes 0.89, 0.48, 1.24 %; 50 modes 0.49, 0.22, 0.39 %; 100 modes 0.14,
#: 0.11, 0.13 % (200 modes, not in the test: 0.043, 0.006, 0.024 %). Tolerances: the measured values + ~30 %.
TRUNCATION = {10: (2.0e-2, 7.0e-3, 1.5e-2), 20: (1.15e-2, 6.3e-3, 1.6e-2), 50: (6.3e-3, 2.8e-3, 5.0e-3),
              100: (1.9e-3, 1.4e-3, 1.6e-3)}
#: The same runs against OpenSees under the shell's own bilinear loads: 100 modes 1.56, 4.96, 2.18 %, and no
#: better with more (1.4-2.1, 4.5-5.1, 2.0-3.3 % from 10 to 100 modes). What stays is the difference between the
#: two loadings of the FE model itself (OpenSees against OpenSees: 1.46, 5.05, 2.16 %): a force between the nodes
#: shared linearly along the path (MITC4's w) against the cubic that cosim interpolates, on shells 2 m long. It is
#: the coarse mesh's, O(h^2) or faster: on 20 shells along the span (1 m) it is 0.31, 0.39, 0.36 %, and 100 modes
#: against the bilinear loads 0.32, 0.42, 0.41 % (measured, not in the test: the mesh costs 10 s more). Relative
#: to the far girder's small peak (0.62 mm, a quarter of the loaded girder's) it looks largest.
BILINEAR = (2.0e-2, 6.5e-2, 2.8e-2)


def test_moving_forces_through_the_imported_modes_match_opensees_direct_integration(prepared):
    """Two forces in two off-centre lanes, opposite directions (:data:`LANES`), through from_opensees +
    ModalBridge + simulate (the compiled coupled step on the deck's modes, the contact rows from the mode
    surface), against OpenSees' Newmark integration of the full model: within the truncation error measured
    above (:data:`TRUNCATION`), which falls with the number of modes; against the shell's bilinear loads,
    within the mesh's own load difference (:data:`BILINEAR`)."""
    errors = {}
    for count in TRUNCATION:
        got = cosim_moving_forces(prepared.bridge, count)
        errors[count] = relative_errors(got, prepared.opensees["cubic"])
        assert np.all(errors[count] <= TRUNCATION[count]), (count, errors[count])
    assert errors[100].max() < 0.5 * errors[10].min() or np.all(errors[100] < errors[10])
    bilinear = relative_errors(cosim_moving_forces(prepared.bridge, 100), prepared.opensees["bilinear"])
    assert np.all(bilinear <= BILINEAR), bilinear
    loads = relative_errors(prepared.opensees["bilinear"], prepared.opensees["cubic"])
    assert np.all(loads > 0.5 * bilinear)  # what stays is the two loadings' difference, not truncation


#: The quarter-car against the dense direct model, 100 modes: the largest difference over the run as a share of
#: the direct's peak of w at the loaded girder, the far girder and the deck edge; of the body's acceleration;
#: and of the contact force's dynamic part (P - W, W = 129.5 kN; its peak 19.3 kN). Measured with Newmark's
#: average acceleration: w 0.16, 0.037, 0.046 %, body 0.072 %, contact force (averaged over each step, below)
#: 0.26 %; with HHT-alpha (-0.3): the same w and body, the contact force itself 0.25 %. Tolerances: +~30 %.
#: (10, 20, 50, 200 modes: w 3.4, 1.2, 0.51, 0.049 % at the loaded girder; body 2.1, 0.71, 0.25, 0.033 %.)
QC_TOLERANCE = {"w": (2.1e-3, 5.0e-4, 6.0e-4), "body": 1.0e-3, "P": 3.5e-3}


@pytest.mark.parametrize("scheme", ["newmark", "hht"])
def test_a_quarter_car_on_the_imported_modes_matches_the_direct_model(prepared, scheme):
    """A quarter-car (:data:`QC`, rigid contact, a 5 mm wavy road) along the loaded girder, through the imported
    modes (100) and simulate, against the same car on the dense direct model of all 709 equations
    (:func:`dense_quarter_car`): deck displacements, body acceleration and contact force within the
    truncation error measured (:data:`QC_TOLERANCE`).

    The contact force holds the wheel's inertia m_w u_w'', the deck's acceleration under the wheel. Under
    Newmark's average-acceleration rule the direct model's stiffest components (the shells' massless rotations,
    modes far above 1/dt) keep an acceleration that alternates from step to step, undamped: the rule's known
    behaviour as omega dt -> infinity (its amplification factor tends to -1), not physics; the direct contact
    force carries it (~300 N, 1.7 % of the dynamic part, 1.6 % still with 200 modes). The mean of two
    consecutive steps, (P_n + P_n+1) / 2, is the force's average over the step, which the rule's own
    velocity update uses (v_n+1 - v_n = dt (a_n + a_n+1) / 2), and it cancels: it is compared. HHT-alpha damps
    those components (rho_inf = 0.54 at alpha = -0.3), and there the contact force itself is compared."""
    hht = -0.3 if scheme == "hht" else 0.0
    settings = SolverSettings(dt=DT, scheme=scheme, hht_alpha=hht if hht else -0.05)
    direct = dense_quarter_car(prepared.model, prepared.mass, prepared.stiffness, hht)
    w, car = cosim_quarter_car(prepared.bridge, 100, settings)
    assert np.all(relative_errors(w, direct["w"]) <= QC_TOLERANCE["w"]), relative_errors(w, direct["w"])
    steps = np.rint(car["t"] / DT).astype(int)
    assert np.all(np.isfinite(direct["P"][steps])) and np.isnan(direct["P"][steps[-1] + 1])  # the same steps on
    body = direct["body_acceleration"][steps]
    assert np.max(np.abs(car["body_acceleration"] - body)) <= QC_TOLERANCE["body"] * np.max(np.abs(body))
    weight = (QC.m_v + QC.m_w) * G
    got, expected = car["contact_force"] - weight, direct["P"][steps] - weight
    if scheme == "newmark":
        got, expected = (got[1:] + got[:-1]) / 2, (expected[1:] + expected[:-1]) / 2
    assert np.max(np.abs(expected)) > 0.1 * weight  # the car interacts: a dynamic part of 15 % of its weight
    assert np.max(np.abs(got - expected)) <= QC_TOLERANCE["P"] * np.max(np.abs(expected))
