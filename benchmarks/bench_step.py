"""Cost of one coupled time step, measured side by side in one run.

Run on demand (not a test)::

    python benchmarks/bench_step.py [--quick] [--out benchmarks/results/step.md]

What is timed, in microseconds of wall time (``time.perf_counter``) per time
step, BLAS pinned to one thread:

1. cosim's compiled step (:meth:`cosim.core.coupling.CoupledSystem.advance` on a
   block of steps) on the paper bridge (40 m, dt = 5 ms) for the ``direct``
   basis and the ``modal`` basis (30 modes; every mode up to 50 Hz), with 0-64
   quarter-cars, the moving-force model, and 20-160 elements per span.
2. A naive solver, the baseline a newcomer would write: every step it
   assembles the coupled system (bridge + quarter-car body DOFs, paper eqs.
   17-19; or only the moving-force load vector) as scipy.sparse matrices and
   solves the Newmark effective system with ``spsolve`` (a new factorisation
   per step). It is checked against cosim first.
3. OpenSeesPy, the tool a VBI researcher would otherwise use: the same beam as
   3D ``elasticBeamColumn`` elements, moving forces as interpolated nodal loads
   re-applied every step, ``analyze(1, dt)`` per step. It is checked against
   cosim's moving-force result first.

4. Decks given by their modes (issue 26, item 7): cosim's step on a
   :class:`cosim.core.modal_bridge.ModalBridge` (the paper bridge's own modes
   through ``from_beam``, 50, 100 and 200 of them) side by side with the
   beam's modal basis on the same modes, with 0, 8 and 64 quarter-cars; and
   the same step on synthetic grid decks of 1e3, 1e4 and 1e5 points (20
   modes, 8 quarter-cars), which shows what locating each contact point on
   the deck costs as the deck grows. These report the median of the
   repetitions as well as the best.

Every configuration is set up once (not timed), then timed ``--reps`` times in
interleaved rounds (round 1 runs every configuration once, then round 2, ...),
and the best repetition counts: on a shared machine each configuration gets
the same chances of a quiet moment, which keeps the ratios honest.

The fleet: vehicles spread along both lanes (y = -3.325 m drives along +x,
y = +3.325 m along -x), at 1 m/s so that every vehicle stays on the deck for
the whole timed block. The traffic arrays are built directly as a
:class:`cosim.core.traffic.TrafficBlock`; a warm-up call compiles (or loads) the
numba kernels before anything is timed.
"""
from __future__ import annotations

import os

# Pin BLAS to one thread before numpy is imported (as the root conftest.py does):
# the step is thousands of tiny dense operations that threads only slow down.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse
import ctypes
import datetime
import math
import platform
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout without installing

import numba  # noqa: E402
from _report import write_report  # noqa: E402 - benchmarks/, on sys.path when a script runs

from cosim.bridges import from_beam  # noqa: E402
from cosim.core import kernels  # noqa: E402
from cosim.core.bases import make_basis  # noqa: E402
from cosim.core.bridge import BridgeModel, ExplicitDamping, build_bridge  # noqa: E402
from cosim.core.coupling import CoupledSystem  # noqa: E402
from cosim.core.modal_bridge import ModalBridge, ModalRatios  # noqa: E402
from cosim.core.modal_deck import ModalDeck  # noqa: E402
from cosim.core.schemes import Scheme  # noqa: E402
from cosim.core.sensors import Sensor  # noqa: E402
from cosim.core.traffic import TrafficBlock  # noqa: E402
from cosim.core.vehicles import MovingForce, QuarterCar, VehicleModel  # noqa: E402
from cosim.run.scenario import load_scenario  # noqa: E402

DT = 0.005  # s, the paper's step
SPEED = 1.0  # m/s: slow, so the fleet stays on the deck for the whole block
LANES = ((-3.325, +1), (+3.325, -1))  # (y, direction): right-hand traffic on both lanes
GRAVITY = 9.81
# The paper's QC-1 (Table 2): 1.0 Hz body bounce, 40 % suspension damping.
QUARTER_CAR = QuarterCar(m_v=1000.0, m_w=100.0, k_v=39478.40, c_v=5026.55)
FORCE = MovingForce(mass=QUARTER_CAR.total_mass)
BASES = (("direct", None, None, "direct"), ("modal", 30, None, "modal-30"), ("modal", None, 50.0, "modal-50Hz"))
DEFAULT_OUT = Path(__file__).resolve().parent / "results" / "step.md"


@dataclass(frozen=True)
class Settings:
    """How much to measure."""

    quick: bool
    reps: int
    cosim_steps: int  # steps per timed cosim block
    naive_steps: int  # steps per timed naive run
    naive_check_steps: int  # steps of the naive-vs-cosim check
    opensees_steps: int  # steps per timed OpenSees run
    vehicles: tuple[int, ...]
    elements: tuple[int, ...]

    @classmethod
    def make(cls, quick: bool, reps: int) -> Settings:
        if quick:
            return cls(True, reps, 500, 60, 400, 150, (0, 1, 4, 8, 16, 64), (20, 40, 80))
        return cls(False, reps, 2000, 300, 2000, 1000, (0, 1, 4, 8, 16, 64), (20, 40, 80, 160))


@dataclass
class Case:
    """One configuration to time: ``run()`` does the timed work and returns (wall s, CPU s) of it."""

    key: str
    solver: str
    model: str
    elements: int
    vehicles: int
    dofs: int
    steps: int
    run: Callable[[], tuple[float, float]] = field(repr=False)
    note: str = ""
    table: str = "main"  # "main", "anatomy" or "decks"
    wall: float = math.inf  # best repetition
    cpu: float = math.nan  # its process CPU time
    walls: list[float] = field(default_factory=list)  # every repetition

    @property
    def median_us_per_step(self) -> float:
        return 1e6 * float(np.median(self.walls)) / self.steps if self.walls else math.nan

    @property
    def us_per_step(self) -> float:
        return 1e6 * self.wall / self.steps


@dataclass
class Report:
    cases: list[Case] = field(default_factory=list)
    checks: list[tuple[str, str, str]] = field(default_factory=list)  # (check, result, comment)
    notes: list[str] = field(default_factory=list)
    facts: dict[str, str] = field(default_factory=dict)  # anatomy: sizes of the direct basis

    def get(self, key: str) -> Case | None:
        return next((c for c in self.cases if c.key == key and math.isfinite(c.wall)), None)

    def check(self, what: str, result: str, comment: str) -> None:
        self.checks.append((what, result, comment))
        print(f"  check: {what}: {result}", flush=True)


def timed(work: Callable[[], object]) -> tuple[float, float]:
    """Wall and process CPU seconds of ``work()``."""
    c0, t0 = time.process_time(), time.perf_counter()
    work()
    return time.perf_counter() - t0, time.process_time() - c0


def measure(cases: list[Case], reps: int) -> None:
    """Interleaved rounds: every case once per round; keep each case's best repetition."""
    for r in range(reps):
        t0 = time.perf_counter()
        for case in cases:
            wall, cpu = case.run()
            case.walls.append(wall)
            if wall < case.wall:
                case.wall, case.cpu = wall, cpu
        print(f"  round {r + 1}/{reps} done ({time.perf_counter() - t0:.1f} s)", flush=True)


# ----------------------------------------------------------------- machine
def _openblas_threads() -> str:
    """Threads each loaded OpenBLAS reports (read from the library, as threadpoolctl does)."""
    try:
        with open("/proc/self/maps") as fh:
            libs = sorted({line.split()[-1] for line in fh if "openblas" in line.lower() and ".so" in line})
    except OSError:
        return "unknown"
    found = []
    for lib in libs:
        try:
            handle = ctypes.CDLL(lib)
        except OSError:
            continue
        for name in ("scipy_openblas_get_num_threads64_", "openblas_get_num_threads64_",
                     "scipy_openblas_get_num_threads", "openblas_get_num_threads"):
            fn = getattr(handle, name, None)
            if fn is not None:
                fn.restype = ctypes.c_int
                found.append(f"{Path(lib).name}: {fn()}")
                break
    return "; ".join(found) or "unknown"


def machine_info() -> dict[str, str]:
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next((line.split(":", 1)[1].strip() for line in fh if line.startswith("model name")), cpu)
    except OSError:
        pass
    try:
        blas = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
        blas_name = f"{blas.get('name', '?')} {blas.get('version', '')}".strip()
    except Exception:  # noqa: BLE001 - older numpy: no dict mode
        blas_name = "unknown"
    try:
        from importlib.metadata import version

        ops_version = version("openseespy")
    except Exception:  # noqa: BLE001
        ops_version = "not installed"
    load = os.getloadavg() if hasattr(os, "getloadavg") else (math.nan,) * 3
    return {
        "CPU": cpu,
        "logical CPUs": str(os.cpu_count()),
        "load average at start (1/5/15 min)": " / ".join(f"{x:.2f}" for x in load),
        "Python": platform.python_version(),
        "numpy / scipy / numba": f"{np.__version__} / {scipy.__version__} / {numba.__version__}",
        "openseespy": ops_version,
        "numpy BLAS": blas_name,
        "BLAS threads": (
            "OMP/OPENBLAS/MKL/BLIS_NUM_THREADS=1 set before numpy was imported; "
            f"OpenBLAS reports {_openblas_threads()}"
        ),
    }


# ------------------------------------------------------------------- setup
def paper_bridge() -> BridgeModel:
    return load_scenario("paper-double-tee").build_bridge()


def refined(paper: BridgeModel, elements: int) -> BridgeModel:
    """The paper bridge with another mesh and the very same alpha, beta."""
    if elements == paper.n_elements:
        return paper
    return build_bridge(
        spans=paper.spans, elements_per_span=elements, material=paper.material, section=paper.section,
        supports=paper.supports, damping=ExplicitDamping(paper.alpha, paper.beta),
    )


def fleet(q: int, model: VehicleModel, steps: int, length: float, speed: float = SPEED) -> TrafficBlock:
    """``q`` vehicles spread over both lanes, on the deck for all ``steps`` steps."""
    travel = speed * steps * DT
    if travel > length - 1.0:
        raise ValueError(f"{steps} steps at {speed} m/s leave the {length} m deck: lower the steps or speed")
    t = DT * np.arange(1, steps + 1)
    x0, y, direction = np.empty(q), np.empty(q), np.empty(q)
    for lane, (lane_y, lane_dir) in enumerate(LANES):
        members = list(range(lane, q, len(LANES)))
        for k, j in enumerate(members):
            s0 = 0.5 + (length - travel - 1.0) * (k + 0.5) / len(members)  # distance already driven
            x0[j] = s0 if lane_dir > 0 else length - s0
            y[j], direction[j] = lane_y, lane_dir
    x = x0[None, :] + direction[None, :] * speed * t[:, None]
    v = np.broadcast_to(direction * speed, (steps, q)).copy()
    return TrafficBlock(
        ids=tuple(f"veh{j}" for j in range(q)), models=(model,) * q, x=x, v=v, a=np.zeros((steps, q)), y=y,
    )


def crossing(model: VehicleModel, length: float, speed: float, y: float = 0.0) -> TrafficBlock:
    """One vehicle crossing the whole deck along +x (from x = 0 to x = L)."""
    steps = int(math.ceil(length / speed / DT))
    x = np.minimum(speed * DT * np.arange(1, steps + 1), length)[:, None]
    return TrafficBlock(("one",), (model,), x, np.full((steps, 1), speed), np.zeros((steps, 1)), np.array([y]))


def head(block: TrafficBlock, steps: int) -> TrafficBlock:
    return TrafficBlock(block.ids, block.models, block.x[:steps], block.v[:steps], block.a[:steps], block.y)


# ------------------------------------------------------------------- cosim
def cosim_factory(bridge: BridgeModel, basis: str, n_modes: int | None = None, cutoff_hz: float | None = None,
                  sensor_y: float = 0.0) -> tuple[Callable[[], CoupledSystem], int]:
    """A maker of fresh coupled systems sharing one basis (built and factorised here, once).

    The systems sample one sensor: the deflection at mid-span, lateral position ``sensor_y``.
    """
    scheme = Scheme.newmark()
    b = make_basis(bridge, DT, scheme, basis, n_modes, cutoff_hz)
    sensors = (Sensor("mid", bridge.length / 2, sensor_y, "displacement"),)
    return (lambda: CoupledSystem(bridge, b, scheme, DT, sensors=sensors)), b.n


def cosim_case(key: str, label: str, name: str, bridge: BridgeModel, make: Callable[[], CoupledSystem], n: int,
               block: TrafficBlock) -> Case:
    t0 = time.perf_counter()
    make().advance(head(block, 5))  # compiles the kernel, or loads numba's cache
    warm = time.perf_counter() - t0
    note = f"first call (numba compile or cache load) {warm:.1f} s" if warm > 0.5 else ""
    steps, q = block.x.shape
    return Case(key, f"cosim {label}", name, bridge.n_elements, q, n, steps,
                lambda: timed(lambda: make().advance(block)), note)


def cosim_midspan(bridge: BridgeModel, block: TrafficBlock, basis: str = "direct") -> np.ndarray:
    make, _ = cosim_factory(bridge, basis)
    return make().advance(block).sensors[:, 0]


@numba.njit(cache=False)
def _repeat_band_solve(cb, b, reps):
    total = 0.0
    for _ in range(reps):
        total += kernels.band_solve(cb, b)[0]
    return total


@numba.njit(cache=False)
def _repeat_products(k_ptr, k_ind, k_dat, m_ptr, m_ind, m_dat, x, out, reps):
    for _ in range(reps):
        kernels.csr_matvec_add(k_ptr, k_ind, k_dat, x, out, 1.0)
        kernels.csr_matvec_add(m_ptr, m_ind, m_dat, x, out, 1.0)


def anatomy_cases(report: Report, paper: BridgeModel, s: Settings) -> list[Case]:
    """The direct step's two bridge-sized operations, each timed alone in a compiled loop."""
    b = make_basis(paper, DT, Scheme.newmark(), "direct")
    rhs = np.random.default_rng(1).standard_normal(b.n)
    out = np.zeros(b.n)
    reps = s.cosim_steps
    solve = lambda: _repeat_band_solve(b.cholesky_rows, rhs, reps)  # noqa: E731
    products = lambda: _repeat_products(  # noqa: E731
        b.K.indptr, b.K.indices, b.K.data, b.M.indptr, b.M.indices, b.M.data, rhs, out, reps)
    solve()  # compile
    products()
    report.facts = {
        "free DOFs": f"{b.n}",
        "half-bandwidth of the effective matrix": f"{b.bandwidth}",
        "nonzeros of K, M (CSR)": f"{b.K.nnz}, {b.M.nnz}",
    }
    ne = paper.n_elements
    return [
        Case("anatomy/solve", "one banded Cholesky solve (`kernels.band_solve`, row storage)", "", ne, 0, b.n,
             reps, lambda: timed(solve), table="anatomy"),
        Case("anatomy/products", "K x and M x (`kernels.csr_matvec_add`, CSR), together", "", ne, 0, b.n,
             reps, lambda: timed(products), table="anatomy"),
    ]


# ------------------------------------------------------------------- naive
def naive_run(bridge: BridgeModel, block: TrafficBlock, gravity: float = GRAVITY) -> np.ndarray:
    """Newmark average acceleration on the assembled coupled system, refactorised every step.

    Unknowns: all bridge DOFs and one body DOF per quarter-car (the wheel
    follows the deck, paper eqs. 13-19; z up, displacements from the static
    equilibrium). Equilibrium at t_{n+1} with the vehicle terms at x_{n+1}:
    the same discrete equations cosim solves, assembled the obvious way.
    Returns the mid-span deflection (x = L/2, y = 0) at every step.
    """
    beta, gamma = 0.25, 0.5
    a0, a1, a2 = 1 / (beta * DT**2), gamma / (beta * DT), 1 / (beta * DT)
    a3, a4, a5 = 1 / (2 * beta) - 1, gamma / beta - 1, DT * (gamma / (2 * beta) - 1)
    steps, q = block.x.shape
    ndof = bridge.ndof
    cars = [j for j, m in enumerate(block.models) if isinstance(m, QuarterCar)]
    nv = len(cars)
    if any(not isinstance(m, (QuarterCar, MovingForce)) for m in block.models):
        raise ValueError("the naive solver knows moving forces and rigid-contact quarter-cars only")
    m_v = np.array([block.models[j].m_v for j in cars])
    m_w = np.array([block.models[j].m_w for j in cars])
    k_v = np.array([block.models[j].k_v for j in cars])
    c_v = np.array([block.models[j].c_v for j in cars])
    weight = np.array([m.total_mass for m in block.models]) * gravity
    Mb, Kb, Cb = bridge.M, bridge.K, bridge.C
    keep = np.concatenate([bridge.free, ndof + np.arange(nv)])
    d, v, a = np.zeros(ndof + nv), np.zeros(ndof + nv), np.zeros(ndof + nv)
    sensor = bridge.deck_point_row(bridge.length / 2, 0.0)
    out = np.empty(steps)
    for k in range(steps):
        rows = [bridge.deck_point_row(float(block.x[k, j]), float(block.y[j])) for j in range(q)]
        r_idx = np.repeat(np.arange(q), 14)
        c_idx = np.concatenate([r.dofs for r in rows])
        N, Nx, Nxx = (sp.csr_matrix((np.concatenate([r.values[o] for r in rows]), (r_idx, c_idx)), shape=(q, ndof))
                      for o in range(3))
        F = np.zeros(ndof + nv)
        F[:ndof] = -(N.T @ weight)  # vehicle weights, downward
        if nv:
            vel = block.v[k, cars]
            Nq, Nxq, Nxxq = N[cars], Nx[cars], Nxx[cars]
            D = sp.diags
            Mbb = Mb + Nq.T @ D(m_w) @ Nq
            Cbb = Cb + Nq.T @ D(2 * vel * m_w) @ Nxq + Nq.T @ D(c_v) @ Nq
            Kbb = Kb + Nq.T @ D(vel**2 * m_w) @ Nxxq + Nq.T @ D(vel * c_v) @ Nxq + Nq.T @ D(k_v) @ Nq
            Mc = sp.bmat([[Mbb, None], [None, D(m_v)]], format="csr")
            Cc = sp.bmat([[Cbb, -Nq.T @ D(c_v)], [-D(c_v) @ Nq, D(c_v)]], format="csr")
            Kc = sp.bmat([[Kbb, -Nq.T @ D(k_v)], [-(D(k_v) @ Nq + D(vel * c_v) @ Nxq), D(k_v)]], format="csr")
        else:
            Mc, Cc, Kc = Mb, Cb, Kb
        K_eff = (Kc + a0 * Mc + a1 * Cc).tocsr()[keep][:, keep].tocsc()
        rhs = F + Mc @ (a0 * d + a2 * v + a3 * a) + Cc @ (a1 * d + a4 * v + a5 * a)
        d_new = np.zeros_like(d)
        d_new[keep] = spla.spsolve(K_eff, rhs[keep])
        a_new = a0 * (d_new - d) - a2 * v - a3 * a
        v = v + DT * ((1 - gamma) * a + gamma * a_new)
        d, a = d_new, a_new
        out[k] = sensor.values[0] @ d[sensor.dofs]
    return out


# ---------------------------------------------------------------- OpenSees
def import_opensees():
    try:
        import openseespy.opensees as ops
    except Exception as exc:  # noqa: BLE001 - ImportError, or a missing libblas/liblapack (OSError)
        return None, f"{type(exc).__name__}: {exc}"
    return ops, ""


def opensees_build(ops, bridge: BridgeModel, element: str = "elasticBeamColumn", consistent_mass: bool = True) -> int:
    """The bridge as a 3D OpenSees frame; returns the mid-span node tag.

    ``geomTransf Linear`` with vecxz = global Z: local y = global Y (lateral),
    local z = global Z (up). OpenSees' ``Iy`` (bending in the local x-z plane)
    is then our ``I_y`` (vertical bending) and ``Iz`` our ``I_z``. Supports:
    u, v, w and the twist held at both ends, bending rotations free (as cosim's
    rigid end sections, which also hold warping: OpenSees has no warping DOF).
    """
    sec, mat = bridge.section, bridge.material
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, x in enumerate(bridge.nodes_x):
        ops.node(i + 1, float(x), 0.0, 0.0)
    n = bridge.n_nodes
    ops.fix(1, 1, 1, 1, 1, 0, 0)
    ops.fix(n, 1, 1, 1, 1, 0, 0)
    ops.geomTransf("Linear", 1, 0.0, 0.0, 1.0)
    mass = mat.rho * sec.A  # kg/m
    for e in range(bridge.n_elements):
        if element == "elasticBeamColumn":
            ops.element("elasticBeamColumn", e + 1, e + 1, e + 2, sec.A, mat.E, mat.G, sec.J, sec.I_y, sec.I_z, 1,
                        "-mass", mass, *(["-cMass"] if consistent_mass else []))
        else:  # shear-deformable check
            ops.element("ElasticTimoshenkoBeam", e + 1, e + 1, e + 2, mat.E, mat.G, sec.A, sec.J, sec.I_y, sec.I_z,
                        sec.A_sy, sec.A_sz, 1, "-mass", mass, "-cMass")
    ops.rayleigh(bridge.alpha, bridge.beta, 0.0, 0.0)
    ops.timeSeries("Constant", 1)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.algorithm("Linear")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    mid = int(np.argmin(np.abs(bridge.nodes_x - bridge.length / 2)))
    return mid + 1


def opensees_run(ops, bridge: BridgeModel, block: TrafficBlock, mid: int, gravity: float = GRAVITY,
                 at_y: float = 0.0) -> np.ndarray:
    """Moving forces as interpolated nodal loads, pattern re-created every step.

    Returns the mid-span deflection of the deck point at lateral position ``at_y`` per step
    (``w + (y - y_S) theta_x``, as cosim's sensors).
    """
    steps, q = block.x.shape
    weight = np.array([m.total_mass for m in block.models]) * gravity
    lever = block.y - bridge.section.y_s
    nodes_x = bridge.nodes_x
    n_el = bridge.n_elements
    out = np.empty(steps)
    fz = np.zeros(bridge.n_nodes)
    mx = np.zeros(bridge.n_nodes)
    for k in range(steps):
        if k > 0:
            ops.remove("loadPattern", 1)
        ops.pattern("Plain", 1, 1)
        fz[:] = 0.0
        mx[:] = 0.0
        for j in range(q):
            x = block.x[k, j]
            if not 0.0 <= x <= bridge.length:
                continue
            e = min(max(int(np.searchsorted(nodes_x, x, side="right")) - 1, 0), n_el - 1)
            xi = (x - nodes_x[e]) / (nodes_x[e + 1] - nodes_x[e])
            f = -weight[j]
            fz[e] += (1 - xi) * f
            fz[e + 1] += xi * f
            mx[e] += (1 - xi) * f * lever[j]  # a downward load on the left (y > 0) twists negatively
            mx[e + 1] += xi * f * lever[j]
        for node in np.flatnonzero(fz):
            ops.load(int(node) + 1, 0.0, 0.0, float(fz[node]), float(mx[node]), 0.0, 0.0)
        if ops.analyze(1, DT) != 0:
            raise RuntimeError(f"OpenSees analyze failed at step {k}")
        out[k] = ops.nodeDisp(mid, 3)
        if at_y:
            out[k] += (at_y - bridge.section.y_s) * ops.nodeDisp(mid, 4)
    return out


# -------------------------------------------------------------- the parts
def cosim_cases(report: Report, paper: BridgeModel, s: Settings) -> list[Case]:
    print("cosim: building bases, compiling kernels", flush=True)
    cases = []
    ne = paper.n_elements
    for basis, n_modes, cutoff, label in BASES:
        make, n = cosim_factory(paper, basis, n_modes, cutoff)
        runs = [(QUARTER_CAR, "qc", "quarter-car", q) for q in s.vehicles]
        runs += [(FORCE, "mf", "moving force", q) for q in (1, 8)]
        for model, tag, name, q in runs:
            block = fleet(q, model, s.cosim_steps, paper.length)
            cases.append(cosim_case(f"{label}/{tag}/{ne}/{q}", label, name, paper, make, n, block))
    for n_el in s.elements:
        if n_el == ne:
            continue
        bridge = refined(paper, n_el)
        block = fleet(8, QUARTER_CAR, s.cosim_steps, bridge.length)
        for basis, n_modes, cutoff, label in BASES:
            make, n = cosim_factory(bridge, basis, n_modes, cutoff)
            cases.append(cosim_case(f"{label}/qc/{n_el}/8", label, "quarter-car", bridge, make, n, block))
    return cases


def naive_cases(report: Report, paper: BridgeModel, s: Settings) -> list[Case]:
    print("naive solver: checking against cosim", flush=True)
    cases = []
    for model, tag, name in ((FORCE, "mf", "moving force"), (QUARTER_CAR, "qc", "quarter-car")):
        check = fleet(8, model, s.naive_check_steps, paper.length)
        w_ref = cosim_midspan(paper, check)
        w_naive = naive_run(paper, check)
        peak = float(np.max(np.abs(w_ref)))
        rel = float(np.max(np.abs(w_naive - w_ref))) / peak
        report.check(
            f"naive vs cosim direct: 8 {name}s, mid-span w, {s.naive_check_steps} steps",
            f"max diff / peak = {rel:.1e}",
            f"peak {1e3 * peak:.4f} mm; the same discrete equations, so round-off only",
        )
        block = fleet(8, model, s.naive_steps, paper.length)
        nv = 8 if model is QUARTER_CAR else 0
        run = lambda block=block: timed(lambda: naive_run(paper, block))  # noqa: E731
        cases.append(Case(f"naive/{tag}/{paper.n_elements}/8", "naive sparse", name, paper.n_elements, 8,
                          len(paper.free) + nv, s.naive_steps, run))
    return cases


def opensees_cases(report: Report, paper: BridgeModel, s: Settings) -> list[Case]:
    print("OpenSeesPy: checking against cosim", flush=True)
    ops, why = import_opensees()
    if ops is None:
        msg = f"OpenSeesPy skipped: cannot import openseespy ({why}); see benchmarks/README.md"
        print("  " + msg, flush=True)
        report.notes.append(msg)
        return []
    # Verification: one slow moving force on the axis, crossing the whole deck.
    check = crossing(FORCE, paper.length, speed=4.0)
    w_ref = cosim_midspan(paper, check)
    peak = float(np.max(np.abs(w_ref)))
    for element, label, comment in (
        ("elasticBeamColumn", "elasticBeamColumn (the timed model)",
         "expected: elasticBeamColumn has no shear deformation (about 3 % of the static mid-span deflection "
         "here: 12 E I_y / (G A_sz L^2) = {shear:.1f} %), no warping; loads lumped linearly to nodes"),
        ("ElasticTimoshenkoBeam", "ElasticTimoshenkoBeam (same, with shear areas)",
         "adding shear deformation closes the gap: what is left is load lumping and rotary/warping inertia"),
    ):
        try:
            mid = opensees_build(ops, paper, element)
            w_ops = opensees_run(ops, paper, check, mid)
        except Exception as exc:  # noqa: BLE001 - the shear check is optional
            report.check(f"OpenSees {label} vs cosim direct", "not run", f"{type(exc).__name__}: {exc}")
            continue
        sec, mat = paper.section, paper.material
        shear = 100 * 12 * mat.E * sec.I_y / (mat.G * sec.A_sz * paper.length**2)
        peak_ops = float(np.max(np.abs(w_ops)))
        rel = float(np.max(np.abs(w_ops - w_ref))) / peak
        report.check(
            f"OpenSees {label} vs cosim direct: one moving force at 4 m/s on the axis, mid-span w",
            f"peak {1e3 * peak_ops:.4f} vs {1e3 * peak:.4f} mm ({100 * (peak_ops / peak - 1):+.2f} %); "
            f"max diff / peak = {100 * rel:.2f} %",
            comment.format(shear=shear),
        )
    # Not a pass/fail check: the same force over the left web, deflection under it. OpenSees'
    # beam has St Venant torsion only, cosim's also warping (Vlasov, warping held at the ends).
    y_web = LANES[1][0]
    check = crossing(FORCE, paper.length, speed=4.0, y=y_web)
    make, _ = cosim_factory(paper, "direct", sensor_y=y_web)
    w_ref = make().advance(check).sensors[:, 0]
    mid = opensees_build(ops, paper)
    w_ops = opensees_run(ops, paper, check, mid, at_y=y_web)
    peak, peak_ops = float(np.max(np.abs(w_ref))), float(np.max(np.abs(w_ops)))
    report.check(
        f"for information: OpenSees elasticBeamColumn vs cosim direct, the same force at y = {y_web} m, "
        "mid-span w under it",
        f"peak {1e3 * peak_ops:.4f} vs {1e3 * peak:.4f} mm ({100 * (peak_ops / peak - 1):+.0f} %)",
        "not comparable, and not meant to be: without warping stiffness (E I_w, warping held at the ends) "
        "OpenSees' open section twists far more; the timed runs only need the same work per step",
    )
    cases = []
    # As a researcher would run it (tangent formed and factorised every step), and tuned:
    # `algorithm Linear -factorOnce` is exact here (constant M, C, K) and OpenSees' best case.
    # Consistent mass is the like-for-like setting (cosim's mass is consistent); lumped mass is
    # OpenSees' default and cheaper per step, so it is measured too.
    for q, factor_once, consistent in ((1, False, True), (8, False, True), (8, True, True), (8, False, False)):
        block = fleet(q, FORCE, s.opensees_steps, paper.length)

        def run(block: TrafficBlock = block, factor_once: bool = factor_once,
                consistent: bool = consistent) -> tuple[float, float]:
            mid_ = opensees_build(ops, paper, consistent_mass=consistent)  # not timed
            if factor_once:
                ops.algorithm("Linear", "-factorOnce")
            return timed(lambda: opensees_run(ops, paper, block, mid_))

        key = ("opensees-once" if factor_once else "opensees") + ("" if consistent else "-lumped")
        note = ("algorithm Linear -factorOnce" if factor_once else "algorithm Linear") + (
            ", consistent mass" if consistent else ", lumped mass")
        cases.append(Case(f"{key}/mf/{paper.n_elements}/{q}", "OpenSeesPy", "moving force", paper.n_elements, q,
                          6 * paper.n_nodes - 8, s.opensees_steps, run, note))
    return cases


# ----------------------------------------------------------------- report
DECK_MODES = (50, 100, 200)
DECK_VEHICLES = (0, 8, 64)
DECK_POINTS = ((64, 16), (200, 50), (632, 158))  # grids of ~1e3, 1e4, 1e5 points (along x, across)
DECK_POINT_MODES = 20


def synthetic_deck(n_s: int, n_r: int, length: float, width: float, n_modes: int) -> ModalDeck:
    """A grid deck of ``n_s x n_r`` points with plate-like modes sin(i pi x / L) cos(k pi y / B) (i, k = 1, 2, ...)
    at ascending made-up frequencies: a stand-in of a shell model's slab nodes, for timing only."""
    x, y = np.meshgrid(np.linspace(0.0, length, n_s), np.linspace(-width / 2, width / 2, n_r), indexing="ij")
    pairs = sorted(((i, k) for i in range(1, n_modes + 1) for k in range(0, 4)), key=lambda p: p[0] ** 2 + 4 * p[1])
    pairs = pairs[:n_modes]
    phi = np.array([np.sin(i * np.pi * x / length) * np.cos(k * np.pi * (y / width + 0.5)) for i, k in pairs])
    f_hz = 2.0 * np.arange(1, n_modes + 1)
    return ModalDeck(points=np.column_stack([x.ravel(), y.ravel()]), f_hz=f_hz,
                     phi=phi.reshape(n_modes, -1) * 1e-3, source=f"synthetic {n_s} x {n_r} grid")


def deck_factory(bridge: ModalBridge) -> tuple[Callable[[], CoupledSystem], int]:
    """A maker of fresh coupled systems on a deck given by its modes (one mid-span sensor)."""
    scheme = Scheme.newmark()
    b = make_basis(bridge, DT, scheme, "modal")
    sensors = (Sensor("mid", bridge.length / 2, 0.0, "displacement"),)
    return (lambda: CoupledSystem(bridge, b, scheme, DT, sensors=sensors)), b.n


def deck_cases(report: Report, paper: BridgeModel, s: Settings) -> list[Case]:
    """Modal decks against the beam's modal basis on the same modes; decks of growing point counts."""
    print("decks: building modal decks and bases", flush=True)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    if load > (os.cpu_count() or 1):
        report.notes.append(f"The machine was shared and loaded (load average {load:.1f} on {os.cpu_count()} "
                            "logical CPUs when the decks were set up): medians and bests of one configuration "
                            "can differ by 2x; the bests are the runs that had a core to themselves.")
    cases = []
    # Mass-proportional damping only (the paper's alpha): with its beta the beam's modes above ~110 Hz are damped
    # beyond critical (zeta >= 1), which a modes file cannot hold (from_beam refuses them). The cost of a step
    # does not depend on the damping's values.
    damping = ExplicitDamping(paper.alpha, 0.0)
    beam_bridge = build_bridge(spans=paper.spans, elements_per_span=paper.n_elements, material=paper.material,
                               section=paper.section, supports=paper.supports, damping=damping)
    for n_modes in DECK_MODES:
        beam_make, n = cosim_factory(beam_bridge, "modal", n_modes)
        deck = ModalBridge(from_beam(beam_bridge, n_modes=n_modes), damping)
        deck_make, n_deck = deck_factory(deck)
        points = len(deck.deck.points)
        for q in DECK_VEHICLES:
            block = fleet(q, QUARTER_CAR, s.cosim_steps, paper.length)
            beam = cosim_case(f"beam-modes/qc/{n_modes}/{q}", f"beam modal basis, {n_modes} modes", "quarter-car",
                              paper, beam_make, n, block)
            modal = cosim_case(f"deck-modes/qc/{n_modes}/{q}", f"modal deck (from_beam, {points} points), "
                               f"{n_modes} modes", "quarter-car", paper, deck_make, n_deck, block)
            for case in (beam, modal):
                case.table = "decks"
            cases += [beam, modal]
        # the two give the same numbers (tests/verification/test_modal_beam.py): checked here on the fleet of 8
        block = fleet(8, QUARTER_CAR, 200, paper.length)
        a, b = beam_make().advance(block).sensors[:, 0], deck_make().advance(block).sensors[:, 0]
        report.check(f"modal deck = beam modal basis, {n_modes} modes, 8 quarter-cars, mid-span w",
                     f"{np.max(np.abs(a - b)) / np.max(np.abs(a)):.1e} of the peak", "from_beam's rows are the beam's")
    width = paper.section.deck_y[1] - paper.section.deck_y[0]
    for n_s, n_r in DECK_POINTS:
        t0 = time.perf_counter()
        deck = ModalBridge(synthetic_deck(n_s, n_r, paper.length, width, DECK_POINT_MODES), ModalRatios(0.02))
        make, n = deck_factory(deck)
        built = time.perf_counter() - t0
        block = fleet(8, QUARTER_CAR, s.cosim_steps, paper.length)
        case = cosim_case(f"deck-points/qc/{n_s * n_r}/8", f"synthetic grid deck, {n_s} x {n_r} = {n_s * n_r} "
                          "points", "quarter-car", paper, make, n, block)
        case.table = "decks"
        case.note = (case.note + "; " if case.note else "") + f"deck and basis built in {built:.1f} s (not timed)"
        cases.append(case)
    return cases


def _ratio(report: Report, num: str, den: str) -> float | None:
    a, b = report.get(num), report.get(den)
    return a.us_per_step / b.us_per_step if a and b else None


def ratios(report: Report, s: Settings) -> list[tuple[str, str, str, str]]:
    """(what, measured, target or reference, verdict) rows."""
    out = []

    def add(what: str, value: float | None, target: float | None = None, reference: str = "",
            fmt: str = "") -> None:
        fmt = fmt or ("{:.2f}" if value is not None and value < 10 else "{:.1f}")
        shown = "not measured" if value is None else fmt.format(value)
        if target is None:
            out.append((what, shown, reference, ""))
        else:
            verdict = "" if value is None else ("met" if value >= target else "**missed**")
            out.append((what, shown, f">= {target:g}", verdict))

    ne = 40
    add("OpenSeesPy / cosim direct, 8 moving forces, paper bridge",
        _ratio(report, f"opensees/mf/{ne}/8", f"direct/mf/{ne}/8"), 20)
    add("OpenSeesPy -factorOnce / cosim direct, 8 moving forces",
        _ratio(report, f"opensees-once/mf/{ne}/8", f"direct/mf/{ne}/8"), reference="OpenSees' best case")
    add("OpenSeesPy (lumped mass) / cosim direct, 8 moving forces",
        _ratio(report, f"opensees-lumped/mf/{ne}/8", f"direct/mf/{ne}/8"), reference="OpenSees default mass")
    add("OpenSeesPy (8 moving forces) / cosim direct (8 quarter-cars)",
        _ratio(report, f"opensees/mf/{ne}/8", f"direct/qc/{ne}/8"), reference="cosim doing more physics")
    add("OpenSeesPy / cosim direct, 1 moving force", _ratio(report, f"opensees/mf/{ne}/1", f"direct/mf/{ne}/1"))
    add("cosim direct / modal-30, 8 quarter-cars", _ratio(report, f"direct/qc/{ne}/8", f"modal-30/qc/{ne}/8"), 5)
    add("cosim direct / modal-50Hz, 8 quarter-cars", _ratio(report, f"direct/qc/{ne}/8", f"modal-50Hz/qc/{ne}/8"), 5)
    add("cosim direct / modal-30, 8 moving forces", _ratio(report, f"direct/mf/{ne}/8", f"modal-30/mf/{ne}/8"), 5)
    add("naive sparse / cosim direct, 8 quarter-cars", _ratio(report, f"naive/qc/{ne}/8", f"direct/qc/{ne}/8"))
    add("naive sparse / cosim direct, 8 moving forces", _ratio(report, f"naive/mf/{ne}/8", f"direct/mf/{ne}/8"))
    for label in ("direct", "modal-30", "modal-50Hz"):
        add(f"cosim {label}: 64 / 4 quarter-cars", _ratio(report, f"{label}/qc/{ne}/64", f"{label}/qc/{ne}/4"),
            reference="16 = linear in vehicles", fmt="{:.2f}")
        c0, c8, c64 = (report.get(f"{label}/qc/{ne}/{q}") for q in (0, 8, 64))
        if c0 and c8 and c64:
            per8 = (c8.us_per_step - c0.us_per_step) / 8
            per64 = (c64.us_per_step - c0.us_per_step) / 64
            out.append((f"cosim {label}: added cost per quarter-car, with 8 / with 64 on the deck",
                        f"{per8:.2f} / {per64:.2f} us", "equal = linear", ""))
    lo, hi = min(s.elements), max(s.elements)
    for label in ("direct", "modal-30", "modal-50Hz"):
        add(f"cosim {label}: {hi} / {lo} elements, 8 quarter-cars",
            _ratio(report, f"{label}/qc/{hi}/8", f"{label}/qc/{lo}/8"),
            reference=f"{hi // lo} = linear in elements", fmt="{:.2f}")
    return out


def deck_markdown(report: Report, decks: list[Case]) -> list[str]:
    """The modal decks' tables: per mode count and fleet, the deck beside the beam's modal basis; per point count."""
    lines = [
        "", "## Decks given by their modes (issue 26, item 7)", "",
        "The paper bridge's own modes imported through `from_beam` (41 nodes x 5 lines across = 205 points, a "
        "grid: bicubic Hermite cells, docs/theory.md §13.3) and run as a `ModalBridge` (`DeckModalBasis`: contact "
        "rows from the mode surface, `cosim.core.surface_contact`), beside the beam's own modal basis "
        "(`ModalBasis`: contact rows from the beam's elements) on the same modes, the same quarter-cars and the "
        "same blocks. Microseconds per step: the median of the repetitions (best in brackets).", "",
        "| modes | vehicles | beam modal basis, us/step | modal deck, us/step | deck / beam |",
        "|---:|---:|---:|---:|---:|",
    ]
    for n_modes in DECK_MODES:
        for q in DECK_VEHICLES:
            beam, deck = report.get(f"beam-modes/qc/{n_modes}/{q}"), report.get(f"deck-modes/qc/{n_modes}/{q}")
            if beam is None or deck is None:
                continue
            lines.append(f"| {n_modes} | {q} | {beam.median_us_per_step:.1f} ({beam.us_per_step:.1f}) | "
                         f"{deck.median_us_per_step:.1f} ({deck.us_per_step:.1f}) | "
                         f"{deck.median_us_per_step / beam.median_us_per_step:.2f} |")
    points = [c for c in decks if c.key.startswith("deck-points/")]
    if points:
        lines += [
            "", f"Locating the contact points: synthetic grid decks ({DECK_POINT_MODES} modes, 8 quarter-cars, "
            "no triangles: the grid's rectangle is the surface), from 1e3 to 1e5 points. Each axle's cell is "
            "found by bisection on the grid's lines along and across (O(log n)); a 100-fold larger deck that "
            "costs the same per step shows the lookup is not a scan of the points.", "",
            "| deck | points | us/step, median (best) | note |", "|---|---:|---:|---|",
        ]
        lines += [f"| {c.solver} | {c.key.split('/')[2]} | {c.median_us_per_step:.1f} ({c.us_per_step:.1f}) | "
                  f"{c.note} |" for c in points]
    return lines


def markdown(report: Report, machine: dict[str, str], s: Settings, started: str, wall: float) -> str:
    main = [c for c in report.cases if c.table == "main"]
    anatomy = [c for c in report.cases if c.table == "anatomy"]
    decks = [c for c in report.cases if c.table == "decks"]
    lines = [
        "# Cost of one coupled time step",
        "",
        f"`python benchmarks/bench_step.py{' --quick' if s.quick else ''}`, {started}, {wall:.0f} s in all. "
        f"dt = {DT * 1e3:g} ms, Newmark average acceleration. Microseconds of wall time per step, best of "
        f"{s.reps} repetitions taken in interleaved rounds (the decks' tables: their median, and the best).",
        "",
        "## Machine",
        "",
        "| | |",
        "|---|---|",
        *[f"| {k} | {v} |" for k, v in machine.items()],
        "",
    ]
    main_head = [
        "## Microseconds per step",
        "",
        "Paper bridge (40 m double-tee, Rayleigh 2 %) unless the element count says otherwise; other meshes "
        "keep its alpha and beta. Vehicles: the paper's QC-1 quarter-car (1100 kg) or a moving force of the "
        "same weight, spread over both lanes (y = -3.325 m along +x, y = +3.325 m along -x) at 1 m/s, all on "
        "the deck for the whole timed block. DOFs: the unknowns the solver carries (reduced coordinates for "
        "cosim). CPU/wall: process CPU time over wall time of the best repetition (well below 100 % means "
        "the process was waiting for a core).",
        "",
        "| solver | vehicle model | elements | vehicles | DOFs | us/step | steps timed | CPU/wall | note |",
        "|---|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    if main:
        lines += main_head
    for c in main:
        us = f"{c.us_per_step:.1f}" if math.isfinite(c.wall) else "not run"
        share = f"{100 * c.cpu / c.wall:.0f} %" if math.isfinite(c.wall) and c.wall > 0 else ""
        lines.append(f"| {c.solver} | {c.model} | {c.elements} | {c.vehicles} | {c.dofs} | {us} | {c.steps} | "
                     f"{share} | {c.note} |")
    if main:
        lines += ["", "## Ratios measured in this run", "", "| ratio | measured | target / reference | |",
                  "|---|---:|---|---|"]
        lines += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in ratios(report, s)]
    if decks:
        lines += deck_markdown(report, decks)
    if anatomy:
        lines += [
            "", "## Where the direct step's time goes (paper bridge)", "",
            "The bridge-sized operations of `kernels.direct_block`, each timed alone in a compiled loop. A step "
            "without vehicles does one solve and the K and M products plus O(n) vector updates; with vehicles "
            "it adds a second solve (the Woodbury correction), the q x q capacitance matrix from the dense "
            "inverse (O(q^2)), its LU (O(q^3)) and the per-vehicle contact rows and updates (O(q)).", "",
            "| | |", "|---|---|",
        ]
        lines += [f"| {k} | {v} |" for k, v in report.facts.items()]
        lines += [f"| {c.solver} | {c.us_per_step:.2f} us |" for c in anatomy if math.isfinite(c.wall)]
    lines += ["", "## Checks against cosim, run before the timing", "", "| check | result | comment |",
              "|---|---|---|"]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in report.checks]
    lines += ["", "## Notes", ""]
    lines += [f"- {n}" for n in report.notes]
    lines += [] if not main else [
        "- cosim: `CoupledSystem.advance` on one block of steps, a fresh system per repetition; the basis "
        "(factorisation, dense inverse or modes) is built once and not timed, and a warm-up call compiled "
        "the numba kernels first. The time includes the per-block Python work (road lookup, output arrays) "
        "and one mid-span sensor. modal-30: 30 modes; modal-50Hz: every mode up to 50 Hz (DOFs = how many).",
        "- naive sparse: every step builds the contact rows, assembles M, C, K of bridge + quarter-car bodies "
        "(paper eqs. 17-19) with scipy.sparse and solves the Newmark effective system with `spsolve` "
        "(SuperLU, a new factorisation per step).",
        "- OpenSeesPy: 3D `elasticBeamColumn` (consistent mass rho A, the paper bridge's Rayleigh alpha and "
        "beta), `constraints Plain`, `numberer RCM`, `system BandGeneral`, `algorithm Linear`, Newmark (0.5, "
        "0.25); each step removes and re-creates the load pattern with each force lumped linearly to the two "
        "nodes of its element (vertical force and the torque of its lateral offset), then `analyze(1, dt)`. "
        "Model building is not timed.",
    ]
    if decks:
        lines += [
            "- Decks: `CoupledSystem.advance` on one block, a fresh system per repetition, the basis built once; "
            "the beam for these rows keeps the paper bridge's mesh and mass-proportional damping alpha only "
            "(with its beta the beam's modes above ~110 Hz are damped beyond critical, which a modes file cannot "
            "hold: from_beam refuses them). The cost of a step does not depend on the damping's values.",
        ]
    lines += [
        "- Shared machine with few cores: differences of ~10-20 % between runs are noise; the ratios are "
        "taken within one run, with the repetitions interleaved.",
    ]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Microseconds per coupled time step: cosim, naive, OpenSeesPy.")
    parser.add_argument("--quick", action="store_true", help="fewer steps and meshes (well under a minute)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="Markdown report (default: %(default)s)")
    parser.add_argument("--reps", type=int, default=3, help="repetitions per configuration; the best counts")
    parser.add_argument("--skip", nargs="*", default=(), choices=("cosim", "naive", "opensees", "decks"),
                        help="parts to leave out")
    args = parser.parse_args(argv)
    if args.reps < 1:
        parser.error("`--reps` must be >= 1")
    s = Settings.make(args.quick, args.reps)
    started = datetime.datetime.now().isoformat(timespec="seconds")
    t0 = time.perf_counter()
    machine = machine_info()
    for k, v in machine.items():
        print(f"{k}: {v}")
    paper = paper_bridge()
    report = Report()
    if "cosim" not in args.skip:
        report.cases += cosim_cases(report, paper, s)
        report.cases += anatomy_cases(report, paper, s)
    if "naive" not in args.skip:
        report.cases += naive_cases(report, paper, s)
    if "opensees" not in args.skip:
        report.cases += opensees_cases(report, paper, s)
    if "decks" not in args.skip:
        report.cases += deck_cases(report, paper, s)
    print(f"timing {len(report.cases)} configurations, {s.reps} interleaved rounds", flush=True)
    measure(report.cases, s.reps)
    text = markdown(report, machine, s, started, time.perf_counter() - t0)
    print()
    print(text)
    write_report(text, args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
