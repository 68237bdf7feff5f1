"""Linear vehicles on tyres: any number of contacts, bilateral or unilateral (docs/theory.md §11).

A vehicle of this kind is a linear system of its own DOFs ``z`` (body bounce
and pitch, wheels, ...) with mass, damping and stiffness matrices ``Mv, Cv,
Kv``, standing on the deck through tyres: contact k has a tyre ``k_t, c_t``
between the vehicle point ``b_k . z`` and the deck point under it, stretched
by ``T_k = k_t (b_k.z - w_k - r_k) + c_t (b_k.z' - w_k' - v r_x)`` (dynamic
part; the static load ``W_k`` is carried at rest). The contact force on the
deck is ``P_k = W_k - T_k`` (compression positive). With unilateral contact a
tyre that would pull (``P_k < 0``) leaves the deck: it carries nothing
(``T_k = W_k``) until the wheel comes down onto the deck again.

Inside a step the vehicle's DOFs are eliminated exactly as for the tyre
quarter-car, for all its contacts at once: its deck forces are
``E_k = e0_k - sum_l H_kl (c0_l n0_l + c1_l n1_l) . a`` with a coupling
matrix ``H`` between its contacts, which the block loop folds into the
rank-q update. These functions work on one vehicle (a *group* of consecutive
contact columns); their arrays are described by
:class:`cosim.core.kernels.GroupArrays`.
"""
from __future__ import annotations

import numpy as np

from ..jit import compiled
from ..small_solve import solve_small


@compiled
def _views(g, groups):  # noqa: ANN001, ANN201
    """The vehicle's matrices, state and scratch as views of the flat group arrays."""
    nz, nc = groups.nz[g], groups.ncont[g]
    m0 = groups.moff[g]
    mats = groups.mats
    mv = mats[m0:m0 + nz * nz].reshape((nz, nz))
    cv = mats[m0 + nz * nz:m0 + 2 * nz * nz].reshape((nz, nz))
    kv = mats[m0 + 2 * nz * nz:m0 + 3 * nz * nz].reshape((nz, nz))
    bc = mats[m0 + 3 * nz * nz:m0 + 3 * nz * nz + nc * nz].reshape((nc, nz))
    obs = mats[m0 + 3 * nz * nz + nc * nz:m0 + 3 * nz * nz + 2 * nc * nz].reshape((nc, nz))
    s0 = groups.soff[g]
    st = groups.state
    z = st[s0:s0 + nz]
    zd = st[s0 + nz:s0 + 2 * nz]
    zdd = st[s0 + 2 * nz:s0 + 3 * nz]
    fel = st[s0 + 3 * nz:s0 + 4 * nz]
    a0 = groups.aoff[g]
    ax = groups.aux
    z0dd = ax[a0:a0 + nz]
    gm = ax[a0 + nz:a0 + nz + nz * nc].reshape((nz, nc))
    t0 = ax[a0 + nz + nz * nc:a0 + nz + nz * nc + nc]
    h = ax[a0 + nz + nz * nc + nc:a0 + nz + nz * nc + nc + nc * nc].reshape((nc, nc))
    return mv, cv, kv, bc, obs, z, zd, zdd, fel, z0dd, gm, t0, h


@compiled
def _predictors(z, zd, zdd, dt, beta, gamma):  # noqa: ANN001, ANN201
    z_star = z + dt * zd + (0.5 - beta) * dt * dt * zdd
    zd_star = zd + (1.0 - gamma) * dt * zdd
    return z_star, zd_star


@compiled(inline=True)
def _solve_into(a_mat, b, out):  # noqa: ANN001, ANN201
    """out <- a_mat^{-1} b (a_mat kept: its copy is eliminated; ``out`` may be ``b``)."""
    work = a_mat.copy()
    for r in range(len(b)):
        out[r] = b[r]
    solve_small(work, out)


@compiled
def group_coefficients(g, groups, fleet, kin, step, dots, scheme, e0, c0, c1, c2):  # noqa: ANN001, ANN201
    """Deck-force coefficients of every contact of vehicle ``g`` and its coupling matrix H (docs/theory.md §11.2)."""
    dt, beta, gamma, alpha = scheme.dt, scheme.beta, scheme.gamma, scheme.alpha
    ca = 1.0 + alpha
    b2, g1 = beta * dt * dt, gamma * dt
    first, nc, nz = groups.first[g], groups.ncont[g], groups.nz[g]
    mv, cv, kv, bc, obs, z, zd, zdd, fel, z0dd, gm, t0, h = _views(g, groups)
    z_star, zd_star = _predictors(z, zd, zdd, dt, beta, gamma)
    a_mat = mv + ca * (g1 * cv + b2 * kv)
    r_vec = -ca * (cv @ zd_star + kv @ z_star) + alpha * fel
    mt = np.zeros(nc)
    for k in range(nc):
        j = first + k
        w_static = fleet.weight[j]
        c0[j] = 0.0
        c1[j] = 0.0
        c2[j] = 0.0
        if groups.flying[j]:  # the tyre carries nothing: the vehicle feels its static support missing
            t0[k] = w_static
            r_vec -= ca * w_static * bc[k]
            continue
        k_t, c_t = fleet.params[0, j], fleet.params[1, j]
        v = kin.v[step, j]
        t0[k] = k_t * (bc[k] @ z_star - dots[0, j] - kin.r[step, j]) + \
            c_t * (bc[k] @ zd_star - dots[2, j] - v * dots[1, j] - v * kin.r_x[step, j])
        mt[k] = k_t * b2 + c_t * g1
        for r in range(nz):  # loops, not np.outer and slice assignments: their compiled forms cost seconds to build
            for c in range(nz):
                a_mat[r, c] += ca * mt[k] * (bc[k, r] * bc[k, c])
        r_vec -= ca * t0[k] * bc[k]
        c0[j] = mt[k]
        c1[j] = c_t * v * b2
    _solve_into(a_mat, r_vec, z0dd)
    column = np.zeros(nz)
    for k in range(nc):
        if groups.flying[first + k]:  # a flying tyre couples nothing
            for r in range(nz):
                gm[r, k] = 0.0
            continue
        for r in range(nz):
            column[r] = bc[k, r]
        _solve_into(a_mat, column, column)
        for r in range(nz):
            gm[r, k] = column[r]
    for k in range(nc):
        j = first + k
        for m in range(nc):
            h[k, m] = 0.0
        if groups.flying[j]:
            e0[j] = 0.0
            continue
        e0[j] = ca * (-fleet.weight[j] + t0[k] + mt[k] * (bc[k] @ z0dd))
        for m in range(nc):
            if not groups.flying[first + m]:
                bg = 0.0  # bc[k] . gm[:, m], a strided column: a loop, not '@' (which wants contiguous arrays)
                for i in range(gm.shape[0]):
                    bg += bc[k, i] * gm[i, m]
                h[k, m] = ca * ((1.0 if k == m else 0.0) - ca * mt[k] * bg)


@compiled
def _trial(g, groups, fleet, kin, step, tau0, tau1, scheme):  # noqa: ANN001, ANN201
    """The vehicle's accelerations and tyre forces at the end of the step, given the deck's n0.a and n1.a."""
    dt, beta, gamma, alpha = scheme.dt, scheme.beta, scheme.gamma, scheme.alpha
    ca = 1.0 + alpha
    b2, g1 = beta * dt * dt, gamma * dt
    first, nc = groups.first[g], groups.ncont[g]
    mv, cv, kv, bc, obs, z, zd, zdd, fel, z0dd, gm, t0, h = _views(g, groups)
    ta = np.zeros(nc)
    for k in range(nc):
        j = first + k
        if not groups.flying[j]:
            ta[k] = (fleet.params[0, j] * b2 + fleet.params[1, j] * g1) * tau0[j] + \
                fleet.params[1, j] * kin.v[step, j] * b2 * tau1[j]
    zdd_new = z0dd + ca * (gm @ ta)
    tyre = np.empty(nc)
    for k in range(nc):
        j = first + k
        if groups.flying[j]:
            tyre[k] = fleet.weight[j]
        else:
            tyre[k] = t0[k] + (fleet.params[0, j] * b2 + fleet.params[1, j] * g1) * (bc[k] @ zdd_new) - ta[k]
    return zdd_new, tyre


@compiled
def group_check(g, groups, fleet, kin, step, tau0, tau1, w_end, wd_end, scheme):  # noqa: ANN001, ANN201
    """Unilateral contact: flip the contacts of vehicle ``g`` whose assumed state the trial step contradicts.

    A tyre in contact that would pull leaves the deck; a flying wheel whose tyre
    would be compressed lands. Returns True when a state changed (the step is
    then solved again).
    """
    dt, beta, gamma = scheme.dt, scheme.beta, scheme.gamma
    b2, g1 = beta * dt * dt, gamma * dt
    first, nc = groups.first[g], groups.ncont[g]
    mv, cv, kv, bc, obs, z, zd, zdd, fel, z0dd, gm, t0, h = _views(g, groups)
    zdd_new, tyre = _trial(g, groups, fleet, kin, step, tau0, tau1, scheme)
    z_star, zd_star = _predictors(z, zd, zdd, dt, beta, gamma)
    z_new = z_star + b2 * zdd_new
    zd_new = zd_star + g1 * zdd_new
    changed = False
    for k in range(nc):
        j = first + k
        if fleet.params[2, j] == 0.0:  # bilateral contact
            continue
        if groups.flying[j]:
            v = kin.v[step, j]
            t_lin = fleet.params[0, j] * (bc[k] @ z_new - w_end[j] - kin.r[step, j]) + \
                fleet.params[1, j] * (bc[k] @ zd_new - wd_end[j] - v * kin.r_x[step, j])
            if fleet.weight[j] - t_lin > 0.0:
                groups.flying[j] = False
                changed = True
        elif fleet.weight[j] - tyre[k] < 0.0:
            groups.flying[j] = True
            changed = True
    return changed


@compiled
def group_update(g, groups, fleet, kin, step, dots, scheme, vstate, contact, weighted):  # noqa: ANN001, ANN201
    """Advance vehicle ``g`` once the bridge acceleration is known: its state, contact forces and F_{n+1}."""
    dt, beta, gamma = scheme.dt, scheme.beta, scheme.gamma
    b2, g1 = beta * dt * dt, gamma * dt
    first, nc = groups.first[g], groups.ncont[g]
    mv, cv, kv, bc, obs, z, zd, zdd, fel, z0dd, gm, t0, h = _views(g, groups)
    zdd_new, tyre = _trial(g, groups, fleet, kin, step, dots[5], dots[6], scheme)
    z_star, zd_star = _predictors(z, zd, zdd, dt, beta, gamma)
    z_new = z_star + b2 * zdd_new
    zd_new = zd_star + g1 * zdd_new
    for i in range(len(z)):
        z[i] = z_new[i]
        zd[i] = zd_new[i]
        zdd[i] = zdd_new[i]
    f = cv @ zd_new + kv @ z_new
    for k in range(nc):
        j = first + k
        f += tyre[k] * bc[k]
        contact[j] = fleet.weight[j] - tyre[k]
        weighted[j] = -fleet.weight[j] + tyre[k]
        vstate[0, j] = obs[k] @ z_new
        vstate[1, j] = obs[k] @ zd_new
        vstate[2, j] = obs[k] @ zdd_new
        vstate[3, j] = bc[k] @ z_new
        vstate[4, j] = bc[k] @ zd_new
        vstate[5, j] = bc[k] @ zdd_new
        vstate[6, j] = 0.0
        vstate[7, j] = tyre[k]
    for i in range(len(f)):
        fel[i] = f[i]
