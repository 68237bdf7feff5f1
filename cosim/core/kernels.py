"""The compiled block loop of the coupled vehicle-bridge step: one loop for both bases.

Why compiled: one beam step does a few hundred small operations (contact rows,
vehicle elimination, a rank-q update, banded solves); written with numpy each
cost a Python call of about a microsecond, which made the first (numpy)
version of the step about ten times slower than its arithmetic (~200 us
against ~20 us for the paper bridge with one vehicle; benchmarks/bench_step.py).
The mathematics is docs/theory.md §6; this module is its only implementation.

One loop, :func:`advance_block`, serves both bases and both kinds of deck. The
deck is the seam between the vehicles and the structure (in :func:`advance_block`): a
beam line (its elements' cubics, then projected on the basis) or a surface given
by its modes (each mode's bicubic Hermite patch, docs/theory.md §13: the rows come
out in modal coordinates directly). A contact row is stored
sparsely in the basis' own coordinates (``idx``: which unknowns, ``rv``: the
values of w, w_x, w_xx there): on the direct basis the few element DOFs a
deck point depends on, on a modal basis every mode. Only four operations
differ between the bases and are small compiled functions here:
:func:`internal_rhs` (the bridge's own forces), :func:`project_contacts`
(contact rows into basis coordinates), :func:`solve` (the once-factorised
effective matrix) and :func:`woodbury` (the vehicles' rank-q correction).

Vehicle physics is dispatched per vehicle on its model's ``KIND``
(:mod:`cosim.core.vehicles`). Arrays reach the loop grouped in named tuples;
the loop takes them out once per block and hands each helper it calls at
every step only the arrays it reads: numba counts a reference on every array
of a tuple each time a function takes it, and those counts were a third of
a step (benchmarks/README.md, "Where the time goes"). Every buffer is
allocated once per block, not per step. The loop releases
the GIL, so a log writer thread can encode one block while the next is
computed.
"""
from __future__ import annotations

from collections import namedtuple
from typing import Any

import numpy as np

from .jit import compiled
from .small_solve import solve_small
from .surface_contact import NO_SURFACE, SURFACE_DECK, surface_rows
from .traffic import on_deck
from .vehicles import linear, quarter_car, tyre_quarter_car
from .vehicles.base import LINEAR, MOVING_FORCE, QUARTER_CAR, TYRE_QUARTER_CAR

DIRECT, MODAL = 0, 1
#: A contact point closer than this share of the deck length to a node is on the node (round-off of x).
NODE_SNAP = 1e-12

#: What the loop needs of a basis (arrays a basis does not use are empty).
#: kind: DIRECT | MODAL; n: unknowns.
#: Direct: factor (n, bw+1) banded Cholesky factor by rows; K and M in CSR (k_ptr, k_ind, k_dat, m_ptr,
#: m_ind, m_dat); Rayleigh ray_a, ray_b; inverse (n, n) of the effective matrix; reduced: full DOF ->
#: unknown (-1 restrained). Modal: phi (ndof, n) mass-normalised modes; c_diag, k_diag, a_inv (n,); poly_w,
#: poly_t (n_el, 4, n): on each element, every mode's w and theta_x at the deck as cubics in xi
#: (:func:`modal_polynomials`; empty until the coupled system sets them).
BasisArrays = namedtuple("BasisArrays", [
    "kind", "n", "factor", "k_ptr", "k_ind", "k_dat", "m_ptr", "m_ind", "m_dat", "ray_a", "ray_b", "inverse",
    "reduced", "phi", "c_diag", "k_diag", "a_inv", "poly_w", "poly_t",
], defaults=(np.zeros((0, 0, 0)), np.zeros((0, 0, 0))))
#: The kinds of deck: a beam line (its elements' cubics, then the basis) or a surface given by its modes.
BEAM_DECK = 0
#: The deck: node positions (m), per-element polynomial coefficients of w and theta_x (n_el, 14, 4), the
#: shear centre's y (m), the length (m), the element DOFs a deck point's w depends on (from the element), and
#: the deck surface's lateral extent (m): a wheel beyond it is off the deck (rigid ground) at any x. ``kind``:
#: :data:`BEAM_DECK` or :data:`SURFACE_DECK` (then ``surface`` holds it, the beam's arrays are empty and the
#: basis is the deck's modes).
DeckArrays = namedtuple("DeckArrays", ["nodes_x", "cw", "ct", "y_s", "length", "dofs", "node_dofs", "y_lo", "y_hi",
                                       "kind", "surface"],
                        defaults=(-np.inf, np.inf, BEAM_DECK, NO_SURFACE))
#: dt (s) and the Newmark/HHT parameters.
StepScheme = namedtuple("StepScheme", ["dt", "beta", "gamma", "alpha"])
#: The bridge's state in basis coordinates and F_n, its non-inertial vehicle forces of the last step (HHT).
BridgeState = namedtuple("BridgeState", ["d", "v", "a", "force"])
#: The vehicles (q): model KIND, parameters (PARAM_ROWS, q), weight (N), state (STATE_ROWS, q), lifted now.
Fleet = namedtuple("Fleet", ["kind", "params", "weight", "vstate", "lifted"])
#: Traffic over the block's K steps: contact point x, speed, acceleration along +x (K, q); lateral y (q);
#: road r and its slope r_x under each wheel (K, q); ``path`` (K, q, 5): on a curved path, each wheel's y, unit
#: tangent (tx, ty) and curvature vector (cx, cy) per step (empty: straight along x at ``y``).
Kinematics = namedtuple("Kinematics", ["x", "v", "a", "y", "r", "r_x", "path"], defaults=(np.zeros((0, 0, 5)),))
#: Sensor rows in basis coordinates (s, nnz) and the time derivative each reads (0 d, 1 d', 2 d'');
#: ``every`` (s,): read at the steps whose index is a multiple of it (NaN between); ``step0`` (1,): the index
#: of the block's first step.
SensorRows = namedtuple("SensorRows", ["idx", "vals", "order", "every", "step0"])
#: Linear vehicles on tyres (cosim.core.vehicles.linear), each a group of consecutive contact columns.
#: Per vehicle g: first column, contacts, DOFs; offsets into ``mats`` (Mv, Cv, Kv, contact rows b, body
#: observation rows, flattened), ``state`` (z, z', z'', previous elastic forces) and ``aux`` (step scratch).
#: Per column: ``col`` its vehicle (-1: a one-contact model), ``flying`` (unilateral contact off the deck).
#: ``unilateral``: some contact may leave the deck (the step is then solved until the contact states agree).
GroupArrays = namedtuple("GroupArrays", [
    "first", "ncont", "nz", "moff", "mats", "soff", "state", "aoff", "aux", "col", "flying", "unilateral",
])
#: How often a step is solved again at most when unilateral contacts change state within it.
MAX_CONTACT_SWITCHES = 8
#: What a block records: sensors (K, s); contact force, body u and u'' (K, q); on the deck and lifted off
#: (K, q); counters: lift-off events, lift-off vehicle-steps, solves, the step that diverged (0: none).
BlockOutputs = namedtuple("BlockOutputs", ["sensors", "contact", "body_u", "body_a", "on", "lifted", "counters"])

_on_deck = compiled(on_deck)


# ----------------------------------------------------------------- banded LA
@compiled
def band_solve_into(ur, b, x):  # noqa: ANN001, ANN201
    """x = (U^T U)^{-1} b with U the upper banded Cholesky factor stored by rows: ur[j, k] = U[j, j + k].

    Row storage makes both substitutions run over contiguous memory (an axpy
    forward, a dot product backward), about twice as fast as LAPACK's column
    storage for these narrow bands, and callable without leaving compiled code.
    ``x`` may be ``b`` itself.
    """
    n, w = ur.shape
    for j in range(n):
        x[j] = b[j]
    for j in range(n):
        xj = x[j] / ur[j, 0]
        x[j] = xj
        for k in range(1, min(w, n - j)):
            x[j + k] -= ur[j, k] * xj
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(1, min(w, n - i)):
            s -= ur[i, k] * x[i + k]
        x[i] = s / ur[i, 0]


@compiled
def band_solve(ur, b):  # noqa: ANN001, ANN201
    """(U^T U)^{-1} b as a new array (see :func:`band_solve_into`)."""
    x = np.empty_like(b)
    band_solve_into(ur, b, x)
    return x


@compiled
def csr_matvec_add(indptr, indices, data, x, out, scale):  # noqa: ANN001, ANN201
    """out += scale * A x for A in CSR form."""
    for i in range(out.shape[0]):
        s = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            s += data[k] * x[indices[k]]
        out[i] += scale * s


# ------------------------------------------------------------- contact rows
def modal_polynomials(phi: np.ndarray, deck: Any) -> tuple[np.ndarray, np.ndarray]:
    """Every mode's deck w (at the shear centre) and theta_x on each element as cubics in xi: (n_el, 4, n) each.

    A contact row in modal coordinates is then, per mode, a cubic evaluated
    at the contact point (13 multiply-adds with w_x and w_xx) instead of a sum
    over the element's eight deck DOFs (24): the projection was most of a
    modal step's cost per vehicle (benchmarks/bench_step.py).
    """
    dofs = np.asarray(deck.dofs)
    n_el = deck.cw.shape[0]
    rows = deck.node_dofs * np.arange(n_el)[:, None] + dofs[None, :]  # (n_el, deck DOFs): full DOF numbers
    shapes = phi[rows]  # (n_el, deck DOFs, n)
    poly_w = np.einsum("ekp,ekj->epj", deck.cw[:, dofs, :], shapes)
    poly_t = np.einsum("ekp,ekj->epj", deck.ct[:, dofs, :], shapes)
    return np.ascontiguousarray(poly_w), np.ascontiguousarray(poly_t)


def with_modal_polynomials(arrays: Any, deck: Any) -> Any:
    """A modal basis' :data:`BasisArrays` with its :func:`modal_polynomials` on a beam ``deck``; a direct one, or
    a deck given by its modes (its rows are modal already), as it is."""
    if arrays.kind != MODAL or deck.kind != BEAM_DECK:
        return arrays
    poly_w, poly_t = modal_polynomials(arrays.phi, deck)
    return arrays._replace(poly_w=poly_w, poly_t=poly_t)


@compiled(inline=True)
def contact_rows(x, y, v, deck, elems, vals, geo):  # noqa: ANN001, ANN201
    """Fill the element index and the (3, 14) values of w, w_x, w_xx at each contact point; e = -1 off the deck
    (beyond its ends, or beside its surface).

    ``geo[i]``: the point's xi on its element, its lever y - y_s (m) and the element's length (m).

    docs/theory.md §5.1. At a node, w_xx of the cubic elements jumps: a contact
    point exactly on a node takes the element ahead of it in its direction of
    travel (speed ``v``), so that mirrored crossings see mirrored rows.
    """
    _element_rows(x, y, v, deck.nodes_x, deck.cw, deck.ct, deck.y_s, deck.length, deck.y_lo, deck.y_hi, elems, vals,
                  geo)


@compiled(inline=True)
def _element_rows(x, y, v, nodes_x, cw, ct, y_s, length, y_lo, y_hi, elems, vals, geo):  # noqa: ANN001, ANN201
    """:func:`contact_rows` on the deck's arrays themselves: the block loop calls it at every step, and each named
    tuple an inlined function takes costs a reference count on every array in it (tens at every step)."""
    q = x.shape[0]
    n_el = nodes_x.shape[0] - 1
    for i in range(q):
        elems[i] = -1
        xi_abs = x[i]
        if not _on_deck(xi_abs, length) or not y_lo <= y[i] <= y_hi:
            for k in range(cw.shape[1]):
                vals[i, 0, k] = 0.0
                vals[i, 1, k] = 0.0
                vals[i, 2, k] = 0.0
            continue
        e = np.searchsorted(nodes_x, xi_abs, side="right") - 1
        e = min(max(e, 0), n_el - 1)
        snap = NODE_SNAP * length
        if v[i] < 0.0 and e > 0 and xi_abs - nodes_x[e] <= snap:
            e -= 1  # at the node starting element e: the element ahead is e - 1
        elif v[i] >= 0.0 and e < n_el - 1 and nodes_x[e + 1] - xi_abs <= snap:
            e += 1  # at the node ending element e: the element ahead is e + 1
        L = nodes_x[e + 1] - nodes_x[e]
        xi = min(max((xi_abs - nodes_x[e]) / L, 0.0), 1.0)
        lever = y[i] - y_s
        p0 = (1.0, xi, xi * xi, xi * xi * xi)
        p1 = (0.0, 1.0 / L, 2.0 * xi / L, 3.0 * xi * xi / L)
        p2 = (0.0, 0.0, 2.0 / (L * L), 6.0 * xi / (L * L))
        for k in range(cw.shape[1]):
            s0 = s1 = s2 = 0.0
            for p in range(4):
                c = cw[e, k, p] + lever * ct[e, k, p]
                s0 += c * p0[p]
                s1 += c * p1[p]
                s2 += c * p2[p]
            vals[i, 0, k] = s0
            vals[i, 1, k] = s1
            vals[i, 2, k] = s2
        elems[i] = e
        geo[i, 0], geo[i, 1], geo[i, 2] = xi, lever, L


# ----------------------------------------------- basis-specific operations
@compiled(inline=True)
def internal_rhs(kind, k_ptr, k_ind, k_dat, m_ptr, m_ind, m_dat, ray_a, ray_b, c_diag, k_diag, d, v, force,  # noqa: ANN001, ANN201, E501
                 d_star, v_star, tmp, rhs, ca, alpha):
    """rhs = -(1+alpha)(C v* + K d*) + alpha (C v + K d) - alpha F_n  (docs/theory.md (6.2)-(6.4)); the basis'
    arrays (:data:`BasisArrays`) and the state's (``d``, ``v``, ``force``) one by one (see :func:`advance_block`)."""
    n = rhs.shape[0]
    if kind == DIRECT:  # C = ray_a M + ray_b K: two CSR products instead of three
        for j in range(n):
            tmp[j] = d_star[j] + ray_b * v_star[j]
            rhs[j] = 0.0
        csr_matvec_add(k_ptr, k_ind, k_dat, tmp, rhs, -ca)
        csr_matvec_add(m_ptr, m_ind, m_dat, v_star, rhs, -ca * ray_a)
        if alpha != 0.0:
            for j in range(n):
                tmp[j] = d[j] + ray_b * v[j]
                rhs[j] -= alpha * force[j]
            csr_matvec_add(k_ptr, k_ind, k_dat, tmp, rhs, alpha)
            csr_matvec_add(m_ptr, m_ind, m_dat, v, rhs, alpha * ray_a)
    else:
        for j in range(n):
            rhs[j] = -ca * (c_diag[j] * v_star[j] + k_diag[j] * d_star[j])
            if alpha != 0.0:
                rhs[j] += alpha * (c_diag[j] * v[j] + k_diag[j] * d[j] - force[j])


@compiled
def _physical_rows(reduced, dofs, node_dofs, elems, vals, idx, rv):  # noqa: ANN001, ANN201
    """Contact rows at the few reduced DOFs a deck point depends on (-1: restrained or off the deck)."""
    for i in range(elems.shape[0]):
        e = elems[i]
        for kk in range(dofs.shape[0]):
            k = dofs[kk]
            idx[i, kk] = reduced[node_dofs * e + k] if e >= 0 else -1
            rv[i, 0, kk] = vals[i, 0, k]
            rv[i, 1, kk] = vals[i, 1, k]
            rv[i, 2, kk] = vals[i, 2, k]


@compiled(inline=True)
def project_contacts(basis, deck, elems, vals, geo, idx, rv, pidx, prv):  # noqa: ANN001, ANN201
    """Contact rows in basis coordinates: ``idx[i]`` the unknowns (-1: none), ``rv[i, order]`` the values.

    On a modal basis ``idx`` is every mode in order (:func:`advance_block` fills it once) and is not written,
    and each mode's w, w_x, w_xx at the point come from its cubics on the element
    (:func:`modal_polynomials`). A complete modal engine
    (``basis.inverse`` given) also keeps the physical rows (``pidx``, ``prv``)
    for the capacitance matrix.
    """
    _project_rows(basis.kind, basis.reduced, deck.dofs, deck.node_dofs, basis.inverse.shape[0] > 0, basis.n,
                  basis.poly_w, basis.poly_t, elems, vals, geo, idx, rv, pidx, prv)


@compiled(inline=True)
def _project_rows(kind, reduced, dofs, node_dofs, physical, m, pw, pt, elems, vals, geo, idx, rv, pidx, prv):  # noqa: ANN001, ANN201, E501
    """:func:`project_contacts` on the arrays themselves (for the block loop: see :func:`_element_rows`);
    ``physical``: the physical rows are kept too (a complete modal engine); ``m``: the modes."""
    q = elems.shape[0]
    if kind == DIRECT:
        _physical_rows(reduced, dofs, node_dofs, elems, vals, idx, rv)
    else:
        if physical:
            _physical_rows(reduced, dofs, node_dofs, elems, vals, pidx, prv)
        for i in range(q):
            e = elems[i]
            if e < 0:
                for j in range(m):
                    rv[i, 0, j] = 0.0
                    rv[i, 1, j] = 0.0
                    rv[i, 2, j] = 0.0
                continue
            xi, lever, L = geo[i, 0], geo[i, 1], geo[i, 2]
            xi2 = xi * xi
            d1, d2 = 1.0 / L, 1.0 / (L * L)
            for j in range(m):
                a0 = pw[e, 0, j] + lever * pt[e, 0, j]
                a1 = pw[e, 1, j] + lever * pt[e, 1, j]
                a2 = pw[e, 2, j] + lever * pt[e, 2, j]
                a3 = pw[e, 3, j] + lever * pt[e, 3, j]
                rv[i, 0, j] = a0 + a1 * xi + a2 * xi2 + a3 * xi2 * xi
                rv[i, 1, j] = (a1 + 2.0 * a2 * xi + 3.0 * a3 * xi2) * d1
                rv[i, 2, j] = (2.0 * a2 + 6.0 * a3 * xi) * d2


@compiled(inline=True)
def solve(kind, factor, a_inv, b, x, counters):  # noqa: ANN001, ANN201
    """x = A^{-1} b with the once-factorised effective matrix (banded Cholesky ``factor``, or a modal basis'
    diagonal inverse ``a_inv``)."""
    if kind == DIRECT:
        counters[2] += 1
        band_solve_into(factor, b, x)
    else:
        for j in range(b.shape[0]):
            x[j] = b[j] * a_inv[j]


@compiled
def _mix_groups(first_of, ncont, aoff, nzs, aux, S, pz):  # noqa: ANN001, ANN201
    """Rows of a multi-contact vehicle: S <- I + H S~ and pz <- H pz~ with its coupling matrix H (the groups'
    arrays of :data:`GroupArrays`: ``first``, ``ncont``, ``aoff``, ``nz``, ``aux``)."""
    q = S.shape[0]
    for g in range(first_of.shape[0]):
        first, nc = first_of[g], ncont[g]
        a0 = aoff[g]
        nz = nzs[g]
        h0 = a0 + nz + nz * nc + nc
        rows = S[first:first + nc, :].copy()
        pzs = pz[first:first + nc].copy()
        for k in range(nc):
            for c in range(q):
                s = 1.0 if first + k == c else 0.0
                for m in range(nc):
                    s += aux[h0 + k * nc + m] * rows[m, c]
                S[first + k, c] = s
            s = 0.0
            for m in range(nc):
                s += aux[h0 + k * nc + m] * pzs[m]
            pz[first + k] = s


@compiled
def _capacitance(ainv, idx, rv, p, col, S):  # noqa: ANN001, ANN201
    """S = I + P A^-1 U^T from the entries of the dense physical inverse at the rows' few DOFs (``col``: each
    column's vehicle group, -1 for a one-contact model: :data:`GroupArrays`)."""
    q, nnz = idx.shape
    for i in range(q):
        for jv in range(q):
            s = 1.0 if i == jv and col[i] < 0 else 0.0
            for kk in range(nnz):
                r_ = idx[i, kk]
                if r_ < 0:
                    continue
                acc_ = 0.0
                for ll in range(nnz):
                    c_ = idx[jv, ll]
                    if c_ >= 0:
                        acc_ += ainv[r_, c_] * rv[jv, 0, ll]
                s += p[i, kk] * acc_
            S[i, jv] = s


@compiled
def woodbury(kind, inverse, factor, a_inv, idx, rv, p, z_b, S, pz, us, corr, counters, col, first, ncont, aoff, nz,  # noqa: ANN001, ANN201
             aux, coef, pidx, prv, pp):
    """z_b <- (A + U P^T)^{-1} b from z_b = A^{-1} b: the rank-q update (docs/theory.md §6.6, (6.14)-(6.16)).

    Capacitance matrix ``S = I + P A^-1 U^T``: on the direct basis from the
    dense inverse's entries at the rows' few unknowns (no solve per vehicle);
    on a modal basis A is diagonal (a complete modal engine uses the physical
    inverse's entries instead: 64 products per pair rather than one per mode).
    ``coef`` holds the rows' c0, c1, c2. The basis' and the vehicle groups' arrays come one by one, not in
    their named tuples (see :func:`advance_block`).
    """
    q, nnz = idx.shape
    if kind == DIRECT:
        for i in range(q):
            s = 0.0
            for kk in range(nnz):
                j = idx[i, kk]
                if j >= 0:
                    s += p[i, kk] * z_b[j]
            pz[i] = s
        _capacitance(inverse, idx, rv, p, col, S)
        if first.shape[0] > 0:
            _mix_groups(first, ncont, aoff, nz, aux, S, pz)
        solve_small(S, pz)  # pz <- S^-1 pz
        for j in range(us.shape[0]):
            us[j] = 0.0
        for i in range(q):
            for kk in range(nnz):
                j = idx[i, kk]
                if j >= 0:
                    us[j] += rv[i, 0, kk] * pz[i]
        band_solve_into(factor, us, corr)
        counters[2] += 1
        for j in range(z_b.shape[0]):
            z_b[j] -= corr[j]
    else:
        m = a_inv.shape[0]
        for i in range(q):
            s = 0.0
            for j in range(m):
                s += p[i, j] * z_b[j]
            pz[i] = s
        if inverse.shape[0] > 0:
            for i in range(q):
                for kk in range(pidx.shape[1]):
                    pp[i, kk] = coef[0, i] * prv[i, 0, kk] + coef[1, i] * prv[i, 1, kk] + coef[2, i] * prv[i, 2, kk]
            _capacitance(inverse, pidx, prv, pp, col, S)
        else:
            for i in range(q):
                for k in range(q):
                    s = 1.0 if i == k and col[i] < 0 else 0.0
                    for j in range(m):
                        s += p[i, j] * (a_inv[j] * rv[k, 0, j])
                    S[i, k] = s
        if first.shape[0] > 0:
            _mix_groups(first, ncont, aoff, nz, aux, S, pz)
        solve_small(S, pz)  # pz <- S^-1 pz
        for j in range(m):
            c = 0.0
            for k in range(q):
                c += rv[k, 0, j] * pz[k]
            z_b[j] -= a_inv[j] * c


# --------------------------------------------------------- vehicle physics
@compiled(inline=True)
def vehicle_coefficients(kinds, params, vstate, weight, kv, ka, kr, krx, step, dots, dt, beta, gamma, alpha, e0, c0,  # noqa: ANN001, ANN201, E501
                         c1, c2, pred, aux):
    """Every one-contact vehicle's predictors and deck-force coefficients: ``E_i = e0_i - (c0 n0 + c1 n1 + c2
    n2)_i . a``; the fleet's and the block's arrays one by one (see :func:`advance_block`). Linear vehicles
    (``LINEAR``) are left to :func:`cosim.core.vehicles.linear.group_coefficients`, a whole vehicle at once."""
    ca = 1.0 + alpha
    b2, g1 = beta * dt * dt, gamma * dt
    for i in range(kinds.shape[0]):
        kind = kinds[i]
        if kind == LINEAR:
            continue
        pred[0, i] = vstate[0, i] + dt * vstate[1, i] + (0.5 - beta) * dt * dt * vstate[2, i]
        pred[1, i] = vstate[1, i] + (1.0 - gamma) * dt * vstate[2, i]
        pred[2, i] = vstate[3, i] + dt * vstate[4, i] + (0.5 - beta) * dt * dt * vstate[5, i]
        pred[3, i] = vstate[4, i] + (1.0 - gamma) * dt * vstate[5, i]
        e0[i] = -ca * weight[i]
        c0[i] = 0.0
        c1[i] = 0.0
        c2[i] = 0.0
        v, a, r, r_x = kv[step, i], ka[step, i], kr[step, i], krx[step, i]
        if kind == QUARTER_CAR:
            quarter_car.coefficients(i, params, vstate, pred, v, a, r, r_x, dots, b2, g1, ca, alpha,
                                     e0, c0, c1, c2, aux)
        elif kind == TYRE_QUARTER_CAR:
            tyre_quarter_car.coefficients(i, params, vstate, pred, v, a, r, r_x, dots, b2, g1, ca, alpha,
                                          e0, c0, c1, c2, aux)


@compiled(inline=True)
def vehicle_update(kinds, params, vstate, weight, kv, ka, step, dots, dt, beta, gamma, alpha, pred, aux, contact,  # noqa: ANN001, ANN201, E501
                   weighted):
    """Advance the one-contact vehicles once the bridge acceleration is known; fills contact forces (N,
    compression positive) and the non-inertial deck forces (the HHT F_{n+1}). Linear vehicles are left to
    :func:`cosim.core.vehicles.linear.group_update`."""
    ca = 1.0 + alpha
    b2, g1 = beta * dt * dt, gamma * dt
    for i in range(kinds.shape[0]):
        kind = kinds[i]
        if kind == LINEAR:
            continue
        v, a = kv[step, i], ka[step, i]
        n0a, n1a, n2a = dots[5, i], dots[6, i], dots[7, i]
        acc_b = 0.0
        acc_w = 0.0
        susp = 0.0
        tyre = 0.0
        part = 0.0
        elastic = 0.0
        if kind == QUARTER_CAR:
            acc_b, acc_w, susp, tyre, part, elastic = quarter_car.update(
                i, params, vstate, aux, v, a, n0a, n1a, n2a, b2, g1, ca, alpha)
        elif kind == TYRE_QUARTER_CAR:
            acc_b, acc_w, susp, tyre, part, elastic = tyre_quarter_car.update(
                i, params, vstate, aux, v, a, n0a, n1a, n2a, b2, g1, ca, alpha)
        deck = -weight[i] + part
        vstate[0, i] = pred[0, i] + b2 * acc_b
        vstate[1, i] = pred[1, i] + g1 * acc_b
        vstate[2, i] = acc_b
        if kind == TYRE_QUARTER_CAR:  # the wheel is its own DOF
            vstate[3, i] = pred[2, i] + b2 * acc_w
            vstate[4, i] = pred[3, i] + g1 * acc_w
        else:  # the wheel follows the deck
            vstate[3, i] = dots[8, i]
            vstate[4, i] = dots[9, i]
        vstate[5, i] = acc_w
        vstate[6, i] = susp
        vstate[7, i] = tyre
        contact[i] = -deck
        # The HHT F_{n+1}: weight and the elastic force on the deck, not the wheel's inertia
        # (docs/theory.md (6.5)): the suspension for rigid contact, the tyre for a tyre quarter-car.
        weighted[i] = -weight[i] + elastic if kind != MOVING_FORCE else -weight[i]


# ------------------------------------------------------------------- shared
@compiled(inline=True)
def _newmark_update(d, v, a, d_star, v_star, acc, b2, g1):  # noqa: ANN001, ANN201
    """d, v, a of the new step from the predictors and the new acceleration; False if it is not finite."""
    finite = True
    for j in range(d.shape[0]):
        d[j] = d_star[j] + b2 * acc[j]
        v[j] = v_star[j] + g1 * acc[j]
        a[j] = acc[j]
        if not np.isfinite(acc[j]):
            finite = False
    return finite


@compiled(inline=True)
def _record(step, elems, contact, vstate, lifted, flying, on_, contact_, body_u, body_a, lifted_, counters):  # noqa: ANN001, ANN201, E501
    """The step's vehicle outputs (``on_``, ``contact_``, ``body_u``, ``body_a``, ``lifted_``: the block's
    :data:`BlockOutputs`), and lift-off: the one place where it is detected and counted (theory §5.7)."""
    for i in range(elems.shape[0]):
        on = elems[i] >= 0
        on_[step, i] = on
        contact_[step, i] = contact[i] if on else 0.0
        body_u[step, i] = vstate[0, i]
        body_a[step, i] = vstate[2, i]
        now = on and (contact[i] < 0.0 or flying[i])
        lifted_[step, i] = now
        if now:
            counters[1] += 1
            if not lifted[i]:
                counters[0] += 1
        lifted[i] = now


@compiled(inline=True)
def _deck_dots(kind, idx, rv, nnz, u, w, z, with_z, out):  # noqa: ANN001, ANN201
    """Every contact row (w, w_x, w_xx: ``rv[i]``) against basis vectors: ``out[:, i]`` = n0.u, n1.u, n2.u, n0.w,
    n1.w and, with ``with_z``, n0.z, in one pass over each row (one call for all rows: a call per row cost the
    step a reference count on each of its arrays). On a modal basis the row holds every mode in order (no index
    to follow: the loop vectorises); on the direct basis ``idx[i]`` names the unknowns (-1: restrained)."""
    for i in range(rv.shape[0]):
        s0 = s1 = s2 = s3 = s4 = s5 = 0.0
        if kind == MODAL:
            for j in range(nnz):
                s0 += rv[i, 0, j] * u[j]
                s1 += rv[i, 1, j] * u[j]
                s2 += rv[i, 2, j] * u[j]
                s3 += rv[i, 0, j] * w[j]
                s4 += rv[i, 1, j] * w[j]
                if with_z:
                    s5 += rv[i, 0, j] * z[j]
        else:
            for kk in range(nnz):
                j = idx[i, kk]
                if j >= 0:
                    s0 += rv[i, 0, kk] * u[j]
                    s1 += rv[i, 1, kk] * u[j]
                    s2 += rv[i, 2, kk] * u[j]
                    s3 += rv[i, 0, kk] * w[j]
                    s4 += rv[i, 1, kk] * w[j]
                    if with_z:
                        s5 += rv[i, 0, kk] * z[j]
        out[0, i], out[1, i], out[2, i], out[3, i], out[4, i], out[5, i] = s0, s1, s2, s3, s4, s5


@compiled(nogil=True)
def advance_block(basis, deck, scheme, state, fleet, kin, sensors, out, groups):  # noqa: ANN001, ANN201
    """Advance K = kin.x.shape[0] steps; state, fleet and out are updated in place (docs/theory.md §6).

    Stops early when the bridge acceleration turns non-finite (``out.counters[3]`` = that step + 1).
    """
    n = basis.n
    q = fleet.kind.shape[0]
    nnz = deck.dofs.shape[0] if basis.kind == DIRECT else n
    dt, beta, gamma, alpha = scheme.dt, scheme.beta, scheme.gamma, scheme.alpha
    ca = 1.0 + alpha
    b2 = beta * dt * dt
    g1 = gamma * dt
    d, v, a, force = state.d, state.v, state.a, state.force
    idx = np.empty((q, nnz), dtype=np.int64)
    if basis.kind == MODAL:  # every mode, in order, at every step
        for i in range(q):
            for j in range(nnz):
                idx[i, j] = j
    rv = np.empty((q, 3, nnz))
    p = np.empty((q, nnz))
    contact = np.empty(q)
    weighted = np.empty(q)
    dots = np.zeros((10, q))
    sums = np.empty((6, q))
    e0 = np.empty(q)
    c0 = np.empty(q)
    c1 = np.empty(q)
    c2 = np.empty(q)
    pred = np.empty((4, q))
    aux = np.zeros((6, q))
    S = np.empty((q, q))
    pz = np.empty(q)
    d_star = np.empty(n)
    v_star = np.empty(n)
    tmp = np.empty(n)
    rhs = np.empty(n)
    us = np.empty(n)
    corr = np.empty(n)
    z_b = np.empty(n)
    elems = np.empty(q, dtype=np.int64)
    vals = np.empty((q, 3, deck.cw.shape[1]))
    geo = np.empty((q, 3))
    rhs_bridge = np.empty(n)
    tau0 = np.empty(q)
    tau1 = np.empty(q)
    w_end = np.empty(q)
    wd_end = np.empty(q)
    ndeck = deck.dofs.shape[0]
    pidx = np.empty((q, ndeck), dtype=np.int64)
    prv = np.empty((q, 3, ndeck))
    pp = np.empty((q, ndeck))
    coef = np.empty((3, q))
    bs = np.empty((3, 4))
    br = np.empty((3, 4))
    cell = np.empty((3, 4, 4))
    # The arrays the steps read, taken out of their named tuples once: a function (inlined or not) that takes a
    # named tuple costs a reference count on every array in it at every call (hundreds a step, a third of its time).
    kind, deck_kind, physical = basis.kind, deck.kind, basis.inverse.shape[0] > 0
    nodes_x, cw, ct, dofs, reduced, poly_w, poly_t = deck.nodes_x, deck.cw, deck.ct, deck.dofs, basis.reduced, \
        basis.poly_w, basis.poly_t
    y_s, length, node_dofs, y_lo, y_hi = deck.y_s, deck.length, deck.node_dofs, deck.y_lo, deck.y_hi
    kx, kv, ky = kin.x, kin.v, kin.y
    inverse, factor, a_inv, counters = basis.inverse, basis.factor, basis.a_inv, out.counters
    g_col, g_first, g_ncont, g_aoff, g_nz, g_aux = groups.col, groups.first, groups.ncont, groups.aoff, groups.nz, \
        groups.aux
    unilateral, flying = groups.unilateral, groups.flying
    k_ptr, k_ind, k_dat, m_ptr, m_ind, m_dat = basis.k_ptr, basis.k_ind, basis.k_dat, basis.m_ptr, basis.m_ind, \
        basis.m_dat
    ray_a, ray_b, c_diag, k_diag = basis.ray_a, basis.ray_b, basis.c_diag, basis.k_diag
    kinds, params, vstate, weight, lifted = fleet.kind, fleet.params, fleet.vstate, fleet.weight, fleet.lifted
    ka, kr, krx = kin.a, kin.r, kin.r_x
    out_on, out_contact, out_body_u, out_body_a, out_lifted = out.on, out.contact, out.body_u, out.body_a, out.lifted
    s_idx, s_vals, s_order, s_every, s_step0, out_sensors = sensors.idx, sensors.vals, sensors.order, sensors.every, \
        sensors.step0, out.sensors
    for step in range(kx.shape[0]):
        for j in range(n):
            d_star[j] = d[j] + dt * v[j] + (0.5 - beta) * dt * dt * a[j]
            v_star[j] = v[j] + (1.0 - gamma) * dt * a[j]
        internal_rhs(kind, k_ptr, k_ind, k_dat, m_ptr, m_ind, m_dat, ray_a, ray_b, c_diag, k_diag, d, v, force, d_star,
                     v_star, tmp, rhs, ca, alpha)
        # The deck seam: every contact point's rows in the basis' coordinates (idx, rv) and where it is (elems[i]
        # < 0: off the deck). A beam deck evaluates its elements' cubics at the points and projects them on the
        # basis; a deck given by its modes gives the rows in its modal coordinates directly (surface_rows).
        if q > 0:
            if deck_kind == SURFACE_DECK:
                surface_rows(kin, step, deck, elems, rv, bs, br, cell)
            else:
                _element_rows(kx[step], ky, kv[step], nodes_x, cw, ct, y_s, length, y_lo, y_hi, elems, vals, geo)
                _project_rows(kind, reduced, dofs, node_dofs, physical, n, poly_w, poly_t, elems, vals, geo, idx, rv,
                              pidx, prv)
        # Deck motion at the contact points from the predictors: n0.d*, n1.d*, n0.v*, n2.d*, n1.v*.
        _deck_dots(kind, idx, rv, nnz, d_star, v_star, v_star, False, sums)
        for i in range(q):
            dots[0, i], dots[1, i], dots[2, i], dots[3, i], dots[4, i] = sums[0, i], sums[1, i], sums[3, i], \
                sums[2, i], sums[4, i]
        if unilateral:
            for j in range(n):
                rhs_bridge[j] = rhs[j]
        for attempt in range(MAX_CONTACT_SWITCHES + 1):
            if attempt > 0:
                for j in range(n):
                    rhs[j] = rhs_bridge[j]
            vehicle_coefficients(kinds, params, vstate, weight, kv, ka, kr, krx, step, dots, dt, beta, gamma, alpha, e0,
                                 c0, c1, c2, pred, aux)
            for g in range(g_first.shape[0]):  # linear vehicles, each whole at its first column
                linear.group_coefficients(g, groups, fleet, kin, step, dots, scheme, e0, c0, c1, c2)
            for i in range(q):
                if kind == MODAL:
                    for j in range(nnz):
                        p[i, j] = c0[i] * rv[i, 0, j] + c1[i] * rv[i, 1, j] + c2[i] * rv[i, 2, j]
                        rhs[j] += rv[i, 0, j] * e0[i]
                    continue
                for kk in range(nnz):
                    j = idx[i, kk]
                    p[i, kk] = c0[i] * rv[i, 0, kk] + c1[i] * rv[i, 1, kk] + c2[i] * rv[i, 2, kk]
                    if j >= 0:
                        rhs[j] += rv[i, 0, kk] * e0[i]
            solve(kind, factor, a_inv, rhs, z_b, counters)
            if q > 0:
                for i in range(q):
                    coef[0, i], coef[1, i], coef[2, i] = c0[i], c1[i], c2[i]
                woodbury(kind, inverse, factor, a_inv, idx, rv, p, z_b, S, pz, us, corr, counters, g_col, g_first,
                         g_ncont, g_aoff, g_nz, g_aux, coef, pidx, prv, pp)
            if not unilateral or attempt == MAX_CONTACT_SWITCHES:
                break
            # Unilateral contact: does the trial step agree with the contact states it assumed?
            for i in range(q):
                s0 = s1 = 0.0
                for kk in range(nnz):
                    j = idx[i, kk]
                    if j >= 0:
                        s0 += rv[i, 0, kk] * z_b[j]
                        s1 += rv[i, 1, kk] * z_b[j]
                tau0[i], tau1[i] = s0, s1
                w_end[i] = dots[0, i] + b2 * s0
                wd_end[i] = dots[2, i] + g1 * s0 + kv[step, i] * (dots[1, i] + b2 * s1)
            changed = False
            for g in range(g_first.shape[0]):
                if linear.group_check(g, groups, fleet, kin, step, tau0, tau1, w_end, wd_end, scheme):
                    changed = True
            if not changed:
                break
        if kind == MODAL:
            counters[2] += 1  # one (diagonal) solve per step, with or without vehicles
        if not _newmark_update(d, v, a, d_star, v_star, z_b, b2, g1):
            counters[3] = step + 1
            return
        # Deck motion at the contact points after the step: n0.a, n1.a, n2.a, n0.d, n0.v + v n1.d.
        _deck_dots(kind, idx, rv, nnz, a, d, v, True, sums)
        for i in range(q):
            dots[5, i], dots[6, i], dots[7, i], dots[8, i] = sums[0, i], sums[1, i], sums[2, i], sums[3, i]
            dots[9, i] = sums[5, i] + kv[step, i] * sums[4, i]
        vehicle_update(kinds, params, vstate, weight, kv, ka, step, dots, dt, beta, gamma, alpha, pred, aux, contact,
                       weighted)
        for g in range(g_first.shape[0]):  # linear vehicles, each whole at its first column
            linear.group_update(g, groups, fleet, kin, step, dots, scheme, vstate, contact, weighted)
        if alpha != 0.0:
            for j in range(n):
                force[j] = 0.0
            for i in range(q):
                for kk in range(nnz):
                    j = idx[i, kk]
                    if j >= 0:
                        force[j] += rv[i, 0, kk] * weighted[i]
        _record(step, elems, contact, vstate, lifted, flying, out_on, out_contact, out_body_u, out_body_a, out_lifted,
                counters)
        for s_ in range(s_idx.shape[0]):
            every = s_every[s_]
            if every > 1 and (s_step0[0] + step) % every != 0:
                out_sensors[step, s_] = np.nan
                continue
            order = s_order[s_]
            src = d if order == 0 else (v if order == 1 else a)
            acc_ = 0.0
            for k in range(s_idx.shape[1]):
                j = s_idx[s_, k]
                if j >= 0:
                    acc_ += s_vals[s_, k] * src[j]
            out_sensors[step, s_] = acc_
