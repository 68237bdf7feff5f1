"""Classical open thin-walled (Vlasov) section constants: a reference for checking the FE section solver.

:func:`thin_walled_properties` evaluates the textbook formulas on the plate
midlines (docs/theory.md §2 and §10.2, docs/sections.md). The model never uses
it: its sections come from the finite-element solver of
:func:`cosim.core.section.section_from_plates`; this is the independent
reference the tests (``tests/unit/test_section.py``) and reports compare that
solver with, as :mod:`cosim.validation.references` is for the beam.
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from cosim.core.section import NO_WARPING, Plate, SectionProperties, plate_rectangle, validated_plates
from cosim.errors import ModelError

__all__ = ["thin_walled_properties"]

# 3-point Gauss-Legendre on [0, 1]: exact for the quartic q(u)^2 of a plate
# whose shear flow is quadratic.
_GAUSS_U = 0.5 + 0.5 * np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)])
_GAUSS_W = np.array([5.0, 8.0, 5.0]) / 18.0


def _plate_tree(
    rows: list[tuple[float, float, float, float, float]],
) -> tuple[np.ndarray, list[tuple[int, int, float]]]:
    """Nodes and edges of the midline graph; plates are split at T-junctions.

    A web whose end lies inside the deck's midline joins the deck there, so the
    deck can be given as one plate.
    """
    ends = [(r[0], r[1]) for r in rows] + [(r[2], r[3]) for r in rows]
    scale = max(max(abs(c) for p in ends for c in p), max(r[4] for r in rows))
    tol = 1e-9 * scale
    nodes: list[tuple[float, float]] = []

    def node_of(p: tuple[float, float]) -> int:
        for k, q in enumerate(nodes):
            if math.hypot(p[0] - q[0], p[1] - q[1]) <= tol:
                return k
        nodes.append(p)
        return len(nodes) - 1

    plate_ends = [(node_of((r[0], r[1])), node_of((r[2], r[3])), r[4]) for r in rows]
    edges: list[tuple[int, int, float]] = []
    for (n1, n2, t) in plate_ends:
        (y1, z1), (y2, z2) = nodes[n1], nodes[n2]
        length2 = (y2 - y1) ** 2 + (z2 - z1) ** 2
        inner = []
        for k, (y, z) in enumerate(nodes):
            if k in (n1, n2):
                continue
            u = ((y - y1) * (y2 - y1) + (z - z1) * (z2 - z1)) / length2
            dist = abs((y - y1) * (z2 - z1) - (z - z1) * (y2 - y1)) / math.sqrt(length2)
            if 0.0 < u < 1.0 and dist <= tol:
                inner.append((u, k))
        chain = [n1] + [k for _, k in sorted(inner)] + [n2]
        edges.extend((a, b, t) for a, b in zip(chain[:-1], chain[1:]))
    return np.array(nodes, dtype=float), edges


def thin_walled_properties(plates: Sequence[Plate]) -> SectionProperties:
    """Section constants of an open branched plate section by thin-walled theory.

    Classical (Vlasov) formulas on the plate midlines: ``A = sum(b t)``; second
    moments from the midlines plus each plate's own ``b t^3/12`` term;
    ``J = sum(b t^3 / 3)``; shear centre and ``I_w`` from the sectorial
    coordinate accumulated over the plate tree and normalised to the principal
    sectorial coordinate; shear areas from the shear-flow energy
    ``1 / A_s = integral of q^2 / t ds`` for a unit shear force, and the warping
    shear constant ``I_ws = I_w^2 / integral of S_w^2 / t ds`` from the sectorial
    flow ``S_w = integral of omega t ds`` (docs/theory.md §10.2). The shear
    centre, ``I_w`` and the shear flows use midline second moments (no own
    terms), as the closed-form textbook results do.

    The model uses :func:`~cosim.core.section.section_from_plates`; this
    function is for checking it and for reports: it neglects the junction
    overlaps and the warping across the thickness, which matter for thick plates.

    Args:
        plates: midline segments with thicknesses, m; midlines must meet at end
            points or where an end point lies on another plate (a T-junction).

    Returns:
        The constants with ``source="thin-walled theory"``.

    Raises:
        ConfigError: a plate is invalid (the message names its index).
        ModelError: the midlines form a closed cell or do not meet.
    """
    rows = validated_plates(plates)
    nodes, edges = _plate_tree(rows)
    n_nodes = len(nodes)

    adjacency: list[list[int]] = [[] for _ in range(n_nodes)]
    for e, (a, b, _) in enumerate(edges):
        adjacency[a].append(e)
        adjacency[b].append(e)
    # Breadth-first walk from node 0: each edge is stored as (edge, parent, child).
    parent_edge = [-1] * n_nodes
    seen = [False] * n_nodes
    seen[0] = True
    order: list[tuple[int, int, int]] = []
    queue = [0]
    closed = False
    for node in queue:
        for e in adjacency[node]:
            if e == parent_edge[node]:
                continue
            a, b, _ = edges[e]
            other = b if a == node else a
            if seen[other]:
                closed = True
                continue
            seen[other] = True
            parent_edge[other] = e
            order.append((e, node, other))
            queue.append(other)
    if not all(seen):
        raise ModelError(
            "plate midlines do not meet: the thin-walled formulas need plates joined at end points "
            "or T-junctions; use the FE values (section_from_plates)"
        )
    if closed or len(edges) != n_nodes - 1:
        raise ModelError("closed cells not supported by the thin-walled formulas; use the FE values")

    y, z = nodes[:, 0], nodes[:, 1]
    p1 = np.array([edges[e][0] for e, _, _ in order])
    p2 = np.array([edges[e][1] for e, _, _ in order])
    t = np.array([edges[e][2] for e, _, _ in order])
    dy, dz = y[p2] - y[p1], z[p2] - z[p1]
    b = np.hypot(dy, dz)
    bt = b * t
    area = float(bt.sum())
    y_c = float((bt * (y[p1] + y[p2]) / 2).sum() / area)
    z_c = float((bt * (z[p1] + z[p2]) / 2).sum() / area)
    yt, zt = y - y_c, z - z_c

    def integral(f: np.ndarray, g: np.ndarray, pa: np.ndarray, pb: np.ndarray) -> float:
        """Integral of f g dA over the midlines for fields linear on each plate."""
        return float((bt * (2 * f[pa] * g[pa] + f[pa] * g[pb] + f[pb] * g[pa] + 2 * f[pb] * g[pb]) / 6).sum())

    iy_mid = integral(zt, zt, p1, p2)
    iz_mid = integral(yt, yt, p1, p2)
    iyz_mid = integral(yt, zt, p1, p2)
    # Own terms across the thickness: a rectangle b x t rotated to direction (c, s).
    c, s = dy / b, dz / b
    own = bt * t**2 / 12
    I_y = iy_mid + float((own * c**2).sum())
    I_z = iz_mid + float((own * s**2).sum())
    I_yz = iyz_mid - float((own * c * s).sum())

    # Sectorial coordinate with the pole at the centroid, zero at node 0: on a
    # straight plate the lever arm is constant, so omega is linear on each plate.
    omega = np.zeros(n_nodes)
    for _, parent, child in order:
        lever = yt[parent] * (z[child] - z[parent]) - zt[parent] * (y[child] - y[parent])
        omega[child] = omega[parent] + lever
    # Moving the pole by (a, b) changes omega by -a z + b y; S is the pole for
    # which the sectorial products with y and z vanish.
    a_b = np.linalg.solve(
        np.array([[iyz_mid, -iz_mid], [iy_mid, -iyz_mid]]),
        np.array([integral(omega, yt, p1, p2), integral(omega, zt, p1, p2)]),
    )
    y_s, z_s = y_c + float(a_b[0]), z_c + float(a_b[1])
    omega_s = omega - a_b[0] * zt + a_b[1] * yt
    omega_s -= float((bt * (omega_s[p1] + omega_s[p2]) / 2).sum()) / area
    I_w = max(integral(omega_s, omega_s, p1, p2), 0.0)

    def shear_area(alpha: float, beta: float) -> float:
        """1 / integral(q^2/t ds) for the shear flow of d(sigma)/dx = alpha y~ + beta z~."""
        return flow_stiffness(alpha * yt + beta * zt)

    def flow_stiffness(g: np.ndarray) -> float:
        """1 / integral(q^2/t ds) for the shear flow q balancing d(sigma)/dx = g, g linear on each plate."""
        below = np.zeros(n_nodes)  # integral of g dA over the subtree beyond each node
        energy = 0.0
        for k in range(len(order) - 1, -1, -1):
            _, parent, child = order[k]
            g1, g2 = g[parent], g[child]
            u = _GAUSS_U
            q = below[child] + bt[k] * (g1 * (1 - u) + (g2 - g1) * (1 - u**2) / 2)
            energy += b[k] / t[k] * float((_GAUSS_W * q**2).sum())
            below[parent] += below[child] + bt[k] * (g1 + g2) / 2
        return 1.0 / energy

    inertia = np.array([[iz_mid, iyz_mid], [iyz_mid, iy_mid]])
    # Unit V_y: integral of g y~ dA = 1, of g z~ dA = 0 (and the reverse for V_z).
    A_sy = shear_area(*np.linalg.solve(inertia, [1.0, 0.0]))
    A_sz = shear_area(*np.linalg.solve(inertia, [0.0, 1.0]))
    # Secondary torsion (docs/theory.md §10.2): the warping stress -E omega psi' is balanced by the flow
    # q = (T_w / I_w) integral(omega t ds) from the free ends, whose energy defines I_ws = I_w^2 / integral(q^2/t ds).
    i_ps = I_y + I_z + area * ((y_s - y_c) ** 2 + (z_s - z_c) ** 2)
    I_ws = float(I_w**2 * flow_stiffness(omega_s)) if I_w > NO_WARPING * i_ps**2 / area else math.inf

    corners = np.array([pt for r in rows for pt in plate_rectangle(*r)])
    return SectionProperties(
        A=area, y_c=y_c, z_c=z_c, I_y=I_y, I_z=I_z, I_yz=I_yz, y_s=y_s, z_s=z_s,
        J=float((bt * t**2 / 3).sum()), I_w=I_w, A_sy=A_sy, A_sz=A_sz,
        deck_y=(float(corners[:, 0].min()), float(corners[:, 0].max())),
        source="thin-walled theory", I_ws=I_ws,
    )
