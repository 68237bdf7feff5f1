"""A live OpenSeesPy model's modes as a deck given by its modes (:func:`from_opensees`, docs/modal-decks.md).

OpenSeesPy is the user's tool here, never a dependency of cosim: it is imported
inside :func:`from_opensees`, which reads the model the user has built in the
running Python process.

Mass normalisation. ``ops.eigen``'s vectors are mass-normalised by its default
solver (ARPACK), but not by every solver (``-fullGenLapack``'s are off by
percents), so cosim computes each mode's generalised mass itself, without
forming the mass matrix: with every node at rest and its acceleration set to
the mode shape, the nodal reactions OpenSees computes with inertia
(``ops.reactions('-dynamic')``) are ``M phi`` (less the applied loads, which a
second evaluation at zero acceleration removes), so ``phi^T M phi`` is their
dot product with ``phi`` over every node: elements' consistent or lumped mass and
nodal masses included. The model's nodal state is restored afterwards.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.core.checks import one_of
from cosim.core.limits import MAX_DECK_MODES, MAX_DECK_POINTS
from cosim.core.modal_deck import FRAMES, ModalDeck
from cosim.errors import ConfigError, ModelError, first_line

__all__ = ["from_opensees", "generalised_masses"]

SOURCE = "OpenSees model"


def _ops() -> Any:
    try:
        import openseespy.opensees as ops
    except Exception as exc:  # noqa: BLE001 - ImportError, or the shared library's missing BLAS/LAPACK (OSError)
        raise ConfigError(f"from_opensees needs OpenSeesPy in this Python ({type(exc).__name__}: "
                          f"{first_line(exc)}): pip install openseespy (on Linux also libblas3 and liblapack3)"
                          ) from None
    return ops


def _state(ops: Any, tags: Sequence[int]) -> dict[int, tuple[list[float], list[float], list[float]]]:
    return {t: (list(ops.nodeDisp(t)), list(ops.nodeVel(t)), list(ops.nodeAccel(t))) for t in tags}


def _set(ops: Any, state: Mapping[int, tuple[Sequence[float], Sequence[float], Sequence[float]]]) -> None:
    for tag, (disp, vel, acc) in state.items():
        for k, (d, v, a) in enumerate(zip(disp, vel, acc)):
            ops.setNodeDisp(tag, k + 1, float(d), "-commit")
            ops.setNodeVel(tag, k + 1, float(v), "-commit")
            ops.setNodeAccel(tag, k + 1, float(a), "-commit")


def generalised_masses(ops: Any, n_modes: int) -> npt.NDArray[np.float64]:
    """``phi_j^T M phi_j`` of the first ``n_modes`` eigenvectors of the last ``ops.eigen`` (kg per unit squared),
    from the model's own inertia forces (see the module's docstring); the nodal state is restored."""
    tags = [int(t) for t in ops.getNodeTags()]
    saved = _state(ops, tags)
    ndf = {t: len(saved[t][0]) for t in tags}
    try:
        _set(ops, {t: ([0.0] * ndf[t], [0.0] * ndf[t], [0.0] * ndf[t]) for t in tags})
        ops.reactions("-dynamic")
        baseline = {t: np.array(ops.nodeReaction(t), dtype=float) for t in tags}
        out = np.empty(n_modes)
        for j in range(n_modes):
            shape = {t: np.array(ops.nodeEigenvector(t, j + 1), dtype=float) for t in tags}
            for t in tags:
                for k in range(ndf[t]):
                    ops.setNodeAccel(t, k + 1, float(shape[t][k]), "-commit")
            ops.reactions("-dynamic")
            out[j] = sum(float(shape[t] @ (np.array(ops.nodeReaction(t), dtype=float) - baseline[t])) for t in tags)
    finally:
        _set(ops, saved)
        ops.reactions()
    return out


def _eigen(ops: Any, solver: str, n_modes: int, where: str) -> npt.NDArray[np.float64]:
    """``ops.eigen``'s eigenvalues. OpenSees cannot reuse the analysis an earlier ``eigen`` made for itself in a
    model without one ("no EigenSOE has been set"): after a failure the analysis is wiped and eigen tried once
    more (a model that has an analysis of its own gets through the first time)."""
    def run() -> Any:
        return ops.eigen(solver, n_modes) if solver else ops.eigen(n_modes)

    try:
        eigen = run()
    except Exception:  # noqa: BLE001 - OpenSees raises its own error type, its message goes to stderr
        ops.wipeAnalysis()
        try:
            eigen = run()
        except Exception as exc:  # noqa: BLE001
            raise ModelError(f"{where}ops.eigen({n_modes}) failed ({first_line(exc)}; OpenSees prints why on "
                             "stderr); check the model's supports and masses") from None
    return np.asarray(eigen, dtype=float).reshape(-1)


def _plane(vertical_dof: int) -> tuple[int, int]:
    """The deck plane's two coordinate indices for the vertical axis ``vertical_dof - 1``, in cyclic order
    (right-handed with the vertical: X, Y for Z up; Z, X for Y up)."""
    up = vertical_dof - 1
    return (up + 1) % 3, (up + 2) % 3


def from_opensees(deck_nodes: Sequence[int], n_modes: int, *, vertical_dof: int = 3, frame: str = "bridge",
                  axis: tuple[Sequence[float], Sequence[float]] | None = None, slopes: bool = True,
                  surface: bool = True, zeta: float | Sequence[float] | None = None,
                  quantities: Mapping[str, Callable[[Any], float]] | None = None, solver: str = "",
                  ops: Any = None) -> ModalDeck:
    """The modes of the OpenSeesPy model built in this process, at its deck nodes.

    Runs ``ops.eigen(solver, n_modes)``, mass-normalises the eigenvectors (each one's generalised mass
    ``phi^T M phi`` over the whole model computed from its inertia forces: :func:`generalised_masses`), and
    takes the vertical DOF of the deck nodes. The nodes' state (displacements, velocities, accelerations) is
    given back as it was; the analysis is wiped if ``eigen`` fails in it once (OpenSees cannot reuse the one
    an earlier ``eigen`` made for itself).

    Args:
        deck_nodes: tags of the nodes on the deck's surface (where wheels roll), each once.
        n_modes: how many of the lowest modes.
        vertical_dof: the DOF (1-based) of the vertical translation (3: z up). The deck's plane is spanned
            by the other two axes in cyclic order (X, Y for z up).
        frame: "bridge": x along the bridge from the first support line, y to the left; the model's own
            plane axes, or those of ``axis``. "network": the model is built in SUMO's network coordinates;
            they are kept.
        axis: bridge frame only: the bridge axis ((x0, y0), (x1, y1)) in the model's plane coordinates: x is
            measured from (x0, y0) towards (x1, y1), y to its left. Default: the model's own axes.
        slopes: bridge frame only: take ``phi_x = -theta`` from each node's rotation about the lateral axis
            (exact for Euler-Bernoulli beams and Kirchhoff plates; a Reissner-Mindlin shell's rotation
            differs from the slope by its transverse shear strain), when the nodes have rotations.
        surface: the deck's triangles from the model's 3- and 4-node elements whose nodes are all deck nodes
            (a quad split along its shorter diagonal); none found: no triangles.
        zeta: modal damping ratios (one for all modes, or one per mode); None: the scenario's damping.
        quantities: sensor quantities the shapes cannot give, ``"<quantity>:<sensor>"`` -> a function of the
            OpenSeesPy module that returns the quantity's value in the model's current displacements, e.g.
            ``lambda ops: ops.eleResponse(37, "localForce")[10]``: it is called once per mode with every node
            displaced into the mass-normalised mode shape, which gives the quantity's modal value.
        solver: ``ops.eigen``'s solver flag, e.g. "-fullGenLapack"; "" (default): OpenSees' default (ARPACK).
        ops: the OpenSeesPy module (default ``openseespy.opensees``).

    Raises:
        ConfigError: bad arguments (a node not in the model, a frame, ...).
        ModelError: the eigen analysis fails, or finds a mode with zero frequency (a mechanism).
    """
    ops = _ops() if ops is None else ops
    where = f"{SOURCE}: "
    one_of(frame, FRAMES, "frame", where)
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
        raise ConfigError(f"{where}`n_modes` must be an integer >= 1 (got {n_modes!r})")
    MAX_DECK_MODES.check(int(n_modes), f"{where}`n_modes`")
    if vertical_dof not in (1, 2, 3):
        raise ConfigError(f"{where}`vertical_dof` must be 1, 2 or 3, the vertical translation (got {vertical_dof!r})")
    nodes = [int(t) for t in deck_nodes]
    MAX_DECK_POINTS.check(len(nodes), f"{where}`deck_nodes`")
    if len(set(nodes)) != len(nodes):
        raise ConfigError(f"{where}`deck_nodes`: a node appears twice; give each deck node once")
    known = {int(t) for t in ops.getNodeTags()}
    missing = [t for t in nodes if t not in known]
    if missing:
        raise ConfigError(f"{where}`deck_nodes`: node {missing[0]} is not in the model")
    coords = np.array([ops.nodeCoord(t) for t in nodes], dtype=float)
    if coords.ndim != 2 or coords.shape[1] != 3:
        raise ConfigError(f"{where}the model must be 3-D (ndm 3) for a deck (got nodes with {coords.shape[-1]} "
                          "coordinates)")
    a, b = _plane(vertical_dof)
    plane = coords[:, [a, b]]
    if frame == "network" and axis is not None:
        raise ConfigError(f"{where}`axis` maps the model to the bridge frame; a network-frame model keeps its "
                          "coordinates (drop axis, or use frame='bridge')")
    origin, along = np.zeros(2), np.array([1.0, 0.0])
    if axis is not None:
        p0, p1 = (np.asarray(p, dtype=float) for p in axis)
        length = float(np.hypot(*(p1 - p0)))
        if p0.shape != (2,) or p1.shape != (2,) or not length > 0 or not math.isfinite(length):
            raise ConfigError(f"{where}`axis` must be two distinct points ((x0, y0), (x1, y1)) of the model's plane")
        origin, along = p0, (p1 - p0) / length
    left = np.array([-along[1], along[0]])
    points = np.column_stack([(plane - origin) @ along, (plane - origin) @ left])

    lam = _eigen(ops, solver, int(n_modes), where)
    if len(lam) < n_modes or not np.all(np.isfinite(lam)):
        raise ModelError(f"{where}ops.eigen found {len(lam)} of {n_modes} modes; check the model (supports, "
                         "masses) or ask for fewer modes")
    if np.any(lam <= 0):
        j = int(np.flatnonzero(lam <= 0)[0])
        raise ModelError(f"{where}mode {j + 1} has eigenvalue {lam[j]:.3g}: a mechanism; restrain the model")
    masses = generalised_masses(ops, int(n_modes))
    if not np.all(masses > 0):
        raise ModelError(f"{where}a mode has no mass (generalised mass {masses.min():.3g}); check the masses")
    scale = 1.0 / np.sqrt(masses)
    up = vertical_dof  # 1-based DOF of the vertical translation
    phi = np.array([[ops.nodeEigenvector(t, j + 1, up) for t in nodes] for j in range(n_modes)]) * scale[:, None]
    phi_x = None
    if slopes and frame == "bridge" and all(len(ops.nodeDisp(t)) >= 6 for t in nodes):
        # rotation about the lateral axis (left, in the plane axes a, b); w_x = -that rotation
        rot_a, rot_b = 3 + a + 1, 3 + b + 1
        phi_x = -np.array([[left[0] * ops.nodeEigenvector(t, j + 1, rot_a) + left[1] *
                            ops.nodeEigenvector(t, j + 1, rot_b) for t in nodes] for j in range(n_modes)])
        phi_x = phi_x * scale[:, None]
    sign = np.sign(phi[np.arange(n_modes), np.argmax(np.abs(phi), axis=1)])
    sign[sign == 0] = 1.0
    phi = phi * sign[:, None]
    phi_x = None if phi_x is None else phi_x * sign[:, None]
    values = _modal_values(ops, quantities or {}, int(n_modes), scale * sign) if quantities else {}
    zetas = None if zeta is None else np.broadcast_to(np.asarray(zeta, dtype=float), (n_modes,)).copy()
    triangles = _surface(ops, nodes, points) if surface else None
    return ModalDeck(points=points, f_hz=np.sqrt(lam[:n_modes]) / (2.0 * np.pi), phi=phi, frame=frame, phi_x=phi_x,
                     zeta=zetas, modal_mass=np.ones(n_modes), triangles=triangles, quantities=values,
                     source=SOURCE)


def _modal_values(ops: Any, quantities: Mapping[str, Callable[[Any], float]], n_modes: int,
                  scale: npt.NDArray[np.float64]) -> dict[str, npt.NDArray[np.float64]]:
    """Each quantity's value with the model displaced into each scaled mode shape (the state is restored)."""
    tags = [int(t) for t in ops.getNodeTags()]
    saved = _state(ops, tags)
    out = {key: np.empty(n_modes) for key in quantities}
    try:
        _set(ops, {t: ([0.0] * len(d), [0.0] * len(d), [0.0] * len(d)) for t, (d, _, _) in saved.items()})
        for j in range(n_modes):
            for t in tags:
                for k, value in enumerate(ops.nodeEigenvector(t, j + 1)):
                    ops.setNodeDisp(t, k + 1, float(scale[j] * value), "-commit")
            for key, quantity in quantities.items():
                try:
                    out[key][j] = float(quantity(ops))
                except Exception as exc:  # noqa: BLE001 - the caller's function, OpenSees' errors
                    raise ConfigError(f"{SOURCE}: {key}: its function failed for mode {j + 1}: "
                                      f"{type(exc).__name__}: {first_line(exc)}") from None
    finally:
        _set(ops, saved)
        ops.reactions()
    return out


def _surface(ops: Any, nodes: Sequence[int], points: npt.NDArray[np.float64]) -> npt.NDArray[np.int64] | None:
    """Triangles of the model's 3- and 4-node elements (or the corners of 8/9-node ones) on the deck nodes."""
    index = {t: i for i, t in enumerate(nodes)}
    out: list[tuple[int, int, int]] = []
    for element in ops.getEleTags():
        corners = [int(t) for t in ops.eleNodes(element)]
        corners = corners[:4] if len(corners) in (8, 9) else corners
        if len(corners) not in (3, 4) or not all(t in index for t in corners):
            continue
        c = [index[t] for t in corners]
        if len(c) == 3:
            out.append((c[0], c[1], c[2]))
            continue
        d02 = float(np.hypot(*(points[c[0]] - points[c[2]])))
        d13 = float(np.hypot(*(points[c[1]] - points[c[3]])))
        if d02 <= d13:
            out += [(c[0], c[1], c[2]), (c[0], c[2], c[3])]
        else:
            out += [(c[0], c[1], c[3]), (c[1], c[2], c[3])]
    return np.array(out, dtype=np.int64) if out else None
