"""Compiled inner loop of the coupled vehicle-bridge step (numba).

Why compiled: one beam step does a few hundred small operations (contact rows,
vehicle elimination, a rank-q update, banded solves); written with numpy each
cost a Python call of about a microsecond, which made the first (numpy)
version of the step about ten times slower than its arithmetic (measured
while developing it: ~200 us against ~20 us now for the paper bridge with
one vehicle; benchmarks/bench_step.py times this kernel against a naive
sparse solver and OpenSeesPy). The mathematics is documented in
:mod:`cosim.core.coupling`; this module is its only implementation.

Conventions shared by both bases:

* ``vstate`` (8, q): body u, u', u''; wheel u, u', u''; suspension force;
  tyre force (the last two are the HHT ``F_n`` of each vehicle).
* ``kind``: 0 moving force, 1 quarter-car (rigid contact), 2 tyre quarter-car.
* Contact rows: element ``e`` and local values (3, 14) of w, w_x, w_xx.

The block loops release the GIL, so a log writer thread can encode and write
one block while the next is being computed.
"""
from __future__ import annotations

import numpy as np
from numba import njit

MOVING_FORCE, QUARTER_CAR, TYRE_QUARTER_CAR = 0, 1, 2
# Element DOFs that a deck point's vertical displacement depends on: w, theta_x,
# theta_y (through the Timoshenko w field) and psi at both nodes.
_ACTIVE = (2, 3, 4, 6, 9, 10, 11, 13)


# ----------------------------------------------------------------- banded LA
@njit(cache=True)
def band_solve(ur, b):
    """Solve (U^T U) x = b with U the upper banded Cholesky factor stored by rows: ur[j, k] = U[j, j + k].

    Row storage makes both substitutions run over contiguous memory (an axpy
    forward, a dot product backward), about twice as fast as LAPACK's column
    storage for these narrow bands, and callable without leaving compiled code.
    """
    n, w = ur.shape
    x = b.copy()
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
    return x


# ------------------------------------------------------------- contact rows
@njit(cache=True)
def contact_rows(x, y, nodes_x, cw, ct, y_s, length):
    """Element index and (3, 14) values of w, w_x, w_xx at each contact point; e = -1 off the deck."""
    q = x.shape[0]
    n_el = nodes_x.shape[0] - 1
    elems = np.full(q, -1, dtype=np.int64)
    vals = np.zeros((q, 3, 14))
    for i in range(q):
        xi_abs = x[i]
        if xi_abs < 0.0 or xi_abs > length:
            continue
        e = np.searchsorted(nodes_x, xi_abs, side="right") - 1
        e = min(max(e, 0), n_el - 1)
        L = nodes_x[e + 1] - nodes_x[e]
        xi = min(max((xi_abs - nodes_x[e]) / L, 0.0), 1.0)
        lever = y[i] - y_s
        p0 = (1.0, xi, xi * xi, xi * xi * xi)
        p1 = (0.0, 1.0 / L, 2.0 * xi / L, 3.0 * xi * xi / L)
        p2 = (0.0, 0.0, 2.0 / (L * L), 6.0 * xi / (L * L))
        for k in range(14):
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
    return elems, vals


# --------------------------------------------------------- vehicle physics
@njit(cache=True)
def vehicle_coefficients(kind, m_v, m_w, k_v, c_v, k_t, c_t, weight, vstate, speed, acc, r, r_x,
                         w0, w1d, w1v, w2d, w1v1, dt, beta, gamma, alpha):
    """Effective deck force E_i = e0_i - (c0 n0 + c1 n1 + c2 n2)_i . a, and the vehicle predictors.

    ``w0 = n0.d*``, ``w1d = n1.d*``, ``w1v = n0.v*``, ``w2d = n2.d*``, ``w1v1 = n1.v*``.
    Returns e0, c0, c1, c2, pred (4, q): body u*, u'*, wheel u*, u'*; aux (6, q) for the update.
    """
    q = kind.shape[0]
    ca = 1.0 + alpha
    b2, g1 = beta * dt * dt, gamma * dt
    e0 = np.empty(q)
    c0 = np.zeros(q)
    c1 = np.zeros(q)
    c2 = np.zeros(q)
    pred = np.empty((4, q))
    aux = np.zeros((6, q))
    for i in range(q):
        ub = vstate[0, i] + dt * vstate[1, i] + (0.5 - beta) * dt * dt * vstate[2, i]
        vb = vstate[1, i] + (1.0 - gamma) * dt * vstate[2, i]
        uw = vstate[3, i] + dt * vstate[4, i] + (0.5 - beta) * dt * dt * vstate[5, i]
        vw = vstate[4, i] + (1.0 - gamma) * dt * vstate[5, i]
        pred[0, i], pred[1, i], pred[2, i], pred[3, i] = ub, vb, uw, vw
        v, a = speed[i], acc[i]
        e0[i] = -ca * weight[i]
        if kind[i] == QUARTER_CAR:
            m_hat = k_v[i] * b2 + c_v[i] * g1
            den = m_v[i] + ca * m_hat
            h = 2.0 * v * w1v1[i] + v * v * w2d[i] + a * w1d[i]
            F0 = k_v[i] * (ub - w0[i] - r[i]) + c_v[i] * (vb - w1v[i] - v * w1d[i] - v * r_x[i])
            e0[i] += ca * (m_v[i] * F0 + alpha * m_hat * vstate[6, i]) / den - m_w[i] * h
            c0[i] = m_w[i] + ca * m_v[i] / den * m_hat
            c1[i] = m_w[i] * (2.0 * v * g1 + b2 * a) + ca * m_v[i] / den * c_v[i] * v * b2
            c2[i] = m_w[i] * b2 * v * v
            aux[0, i], aux[1, i], aux[2, i], aux[3, i] = F0, h, den, m_hat
        elif kind[i] == TYRE_QUARTER_CAR:
            mv = k_v[i] * b2 + c_v[i] * g1
            mt = k_t[i] * b2 + c_t[i] * g1
            S0 = k_v[i] * (ub - uw) + c_v[i] * (vb - vw)
            T0 = k_t[i] * (uw - w0[i] - r[i]) + c_t[i] * (vw - w1v[i] - v * w1d[i] - v * r_x[i])
            R1 = -ca * S0 + alpha * vstate[6, i]
            R2 = ca * (S0 - T0) - alpha * (vstate[6, i] - vstate[7, i])
            den = (m_v[i] + ca * mv) * (m_w[i] + ca * mv + ca * mt) - (ca * mv) ** 2
            e0[i] += ca * (T0 + mt * ((m_v[i] + ca * mv) * R2 + ca * mv * R1) / den)
            kappa = ca * (1.0 - ca * mt * (m_v[i] + ca * mv) / den)
            c0[i] = kappa * (k_t[i] * b2 + c_t[i] * g1)
            c1[i] = kappa * c_t[i] * v * b2
            aux[0, i], aux[1, i], aux[2, i], aux[3, i], aux[4, i], aux[5, i] = S0, T0, R1, R2, den, 0.0
    return e0, c0, c1, c2, pred, aux


@njit(cache=True)
def vehicle_update(kind, m_v, m_w, k_v, c_v, k_t, c_t, weight, vstate, speed, acc, pred, aux,
                   n0a, n1a, n2a, w_new, w_dot, dt, beta, gamma, alpha, out_contact, out_weighted):
    """Advance the vehicles once the bridge acceleration is known; fills contact forces (N, compression
    positive) and the non-inertial deck forces (the HHT F_{n+1})."""
    q = kind.shape[0]
    ca = 1.0 + alpha
    b2, g1 = beta * dt * dt, gamma * dt
    for i in range(q):
        ub, vb, uw, vw = pred[0, i], pred[1, i], pred[2, i], pred[3, i]
        v, a = speed[i], acc[i]
        acc_b = 0.0
        acc_w = 0.0
        susp = 0.0
        tyre = 0.0
        deck = -weight[i]
        if kind[i] == QUARTER_CAR:
            F0, h, den, m_hat = aux[0, i], aux[1, i], aux[2, i], aux[3, i]
            qa = m_hat * n0a[i] + c_v[i] * v * b2 * n1a[i]
            acc_b = -(ca * (F0 - qa) - alpha * vstate[6, i]) / den
            susp = F0 - qa + m_hat * acc_b
            acc_w = n0a[i] + (2.0 * v * g1 + b2 * a) * n1a[i] + b2 * v * v * n2a[i] + h
            deck += susp - m_w[i] * acc_w
        elif kind[i] == TYRE_QUARTER_CAR:
            S0, T0, R1, R2, den = aux[0, i], aux[1, i], aux[2, i], aux[3, i], aux[4, i]
            mv = k_v[i] * b2 + c_v[i] * g1
            mt = k_t[i] * b2 + c_t[i] * g1
            ta = (k_t[i] * b2 + c_t[i] * g1) * n0a[i] + c_t[i] * v * b2 * n1a[i]
            acc_w = ((m_v[i] + ca * mv) * (R2 + ca * ta) + ca * mv * R1) / den
            acc_b = ((m_w[i] + ca * mv + ca * mt) * R1 + ca * mv * (R2 + ca * ta)) / den
            susp = S0 + mv * (acc_b - acc_w)
            tyre = T0 + mt * acc_w - ta
            deck += tyre
        vstate[0, i] = ub + b2 * acc_b
        vstate[1, i] = vb + g1 * acc_b
        vstate[2, i] = acc_b
        if kind[i] == TYRE_QUARTER_CAR:
            vstate[3, i] = uw + b2 * acc_w
            vstate[4, i] = vw + g1 * acc_w
        else:
            vstate[3, i] = w_new[i]
            vstate[4, i] = w_dot[i]
        vstate[5, i] = acc_w
        vstate[6, i] = susp
        vstate[7, i] = tyre
        out_contact[i] = -deck
        out_weighted[i] = -weight[i] + susp + tyre if kind[i] != MOVING_FORCE else -weight[i]


@njit(cache=True)
def _newmark_update(d, v, a, d_star, v_star, acc, b2, g1):
    """d, v, a of the new step from the predictors and the new acceleration; False if it is not finite."""
    finite = True
    for j in range(d.shape[0]):
        d[j] = d_star[j] + b2 * acc[j]
        v[j] = v_star[j] + g1 * acc[j]
        a[j] = acc[j]
        if not np.isfinite(acc[j]):
            finite = False
    return finite


# ----------------------------------------------------------- direct basis
@njit(cache=True)
def csr_matvec_add(indptr, indices, data, x, out, scale):
    """out += scale * A x for A in CSR form."""
    for i in range(out.shape[0]):
        s = 0.0
        for k in range(indptr[i], indptr[i + 1]):
            s += data[k] * x[indices[k]]
        out[i] += scale * s


@njit(cache=True, nogil=True)
def direct_block(cb, k_ptr, k_ind, k_dat, m_ptr, m_ind, m_dat, ray_a, ray_b, ainv, red_idx,
                 nodes_x, cw, ct, y_s, length,
                 dt, beta, gamma, alpha,
                 d, v, a, force_prev,
                 kind, m_v, m_w, k_v, c_v, k_t, c_t, weight,
                 vstate, lifted, X, V, ACC, Y, R, RX,
                 sens_idx, sens_vals, sens_kind,
                 out_sens, out_contact, out_body_u, out_body_a, out_on, counters):
    """Advance K steps on the full FE basis. State arrays are updated in place.

    K and M are applied in CSR form (the element stiffness is block diagonal
    by field, so CSR touches far fewer entries than the band); the effective
    matrix is solved with its banded Cholesky factor; the Woodbury capacitance
    matrix comes from the dense inverse's 8 x 8 element blocks of the active DOFs.
    """
    n = d.shape[0]
    q = kind.shape[0]
    n_steps = X.shape[0]
    na = len(_ACTIVE)
    ca = 1.0 + alpha
    b2 = beta * dt * dt
    g1 = gamma * dt
    idx = np.empty((q, na), dtype=np.int64)
    rv = np.empty((q, 3, na))  # row values at the active DOFs
    p = np.empty((q, na))
    contact = np.empty(q)
    weighted = np.empty(q)
    dots = np.zeros((10, q))
    S = np.empty((q, q))
    pz = np.empty(q)
    d_star = np.empty(n)
    v_star = np.empty(n)
    tmp = np.empty(n)
    rhs = np.empty(n)
    us = np.empty(n)
    for step in range(n_steps):
        for j in range(n):
            d_star[j] = d[j] + dt * v[j] + (0.5 - beta) * dt * dt * a[j]
            v_star[j] = v[j] + (1.0 - gamma) * dt * a[j]
            tmp[j] = d_star[j] + ray_b * v_star[j]
            rhs[j] = 0.0
        # rhs = -(1+alpha)(C v* + K d*) + alpha (C v + K d) - alpha F_n, C = ray_a M + ray_b K.
        csr_matvec_add(k_ptr, k_ind, k_dat, tmp, rhs, -ca)
        csr_matvec_add(m_ptr, m_ind, m_dat, v_star, rhs, -ca * ray_a)
        if alpha != 0.0:
            for j in range(n):
                tmp[j] = d[j] + ray_b * v[j]
                rhs[j] -= alpha * force_prev[j]
            csr_matvec_add(k_ptr, k_ind, k_dat, tmp, rhs, alpha)
            csr_matvec_add(m_ptr, m_ind, m_dat, v, rhs, alpha * ray_a)
        elems, vals = contact_rows(X[step], Y, nodes_x, cw, ct, y_s, length)
        for i in range(q):
            e = elems[i]
            s0 = s1 = s2 = s3 = s4 = 0.0
            for kk in range(na):
                k = _ACTIVE[kk]
                j = red_idx[7 * e + k] if e >= 0 else -1
                idx[i, kk] = j
                rv[i, 0, kk] = vals[i, 0, k]
                rv[i, 1, kk] = vals[i, 1, k]
                rv[i, 2, kk] = vals[i, 2, k]
                if j >= 0:
                    s0 += vals[i, 0, k] * d_star[j]
                    s1 += vals[i, 1, k] * d_star[j]
                    s2 += vals[i, 0, k] * v_star[j]
                    s3 += vals[i, 2, k] * d_star[j]
                    s4 += vals[i, 1, k] * v_star[j]
            dots[0, i], dots[1, i], dots[2, i], dots[3, i], dots[4, i] = s0, s1, s2, s3, s4
        e0, c0, c1, c2, pred, aux = vehicle_coefficients(
            kind, m_v, m_w, k_v, c_v, k_t, c_t, weight, vstate, V[step], ACC[step], R[step], RX[step],
            dots[0], dots[1], dots[2], dots[3], dots[4], dt, beta, gamma, alpha)
        for i in range(q):
            for kk in range(na):
                j = idx[i, kk]
                p[i, kk] = c0[i] * rv[i, 0, kk] + c1[i] * rv[i, 1, kk] + c2[i] * rv[i, 2, kk]
                if j >= 0:
                    rhs[j] += rv[i, 0, kk] * e0[i]
        z_b = band_solve(cb, rhs)
        counters[2] += 1
        if q > 0:
            for i in range(q):
                s = 0.0
                for kk in range(na):
                    j = idx[i, kk]
                    if j >= 0:
                        s += p[i, kk] * z_b[j]
                pz[i] = s
                for jv in range(q):
                    s = 1.0 if i == jv else 0.0
                    for kk in range(na):
                        r_ = idx[i, kk]
                        if r_ < 0:
                            continue
                        acc_ = 0.0
                        for ll in range(na):
                            c_ = idx[jv, ll]
                            if c_ >= 0:
                                acc_ += ainv[r_, c_] * rv[jv, 0, ll]
                        s += p[i, kk] * acc_
                    S[i, jv] = s
            sol = np.linalg.solve(S, pz)
            for j in range(n):
                us[j] = 0.0
            for i in range(q):
                for kk in range(na):
                    j = idx[i, kk]
                    if j >= 0:
                        us[j] += rv[i, 0, kk] * sol[i]
            corr = band_solve(cb, us)
            counters[2] += 1
            for j in range(n):
                z_b[j] -= corr[j]
        if not _newmark_update(d, v, a, d_star, v_star, z_b, b2, g1):
            counters[3] = step + 1
            return
        for i in range(q):
            s0 = s1 = s2 = s3 = s4 = s5 = 0.0
            for kk in range(na):
                j = idx[i, kk]
                if j >= 0:
                    s0 += rv[i, 0, kk] * a[j]
                    s1 += rv[i, 1, kk] * a[j]
                    s2 += rv[i, 2, kk] * a[j]
                    s3 += rv[i, 0, kk] * d[j]
                    s4 += rv[i, 0, kk] * v[j]
                    s5 += rv[i, 1, kk] * d[j]
            dots[5, i], dots[6, i], dots[7, i], dots[8, i] = s0, s1, s2, s3
            dots[9, i] = s4 + V[step, i] * s5
        vehicle_update(kind, m_v, m_w, k_v, c_v, k_t, c_t, weight, vstate, V[step], ACC[step], pred, aux,
                       dots[5], dots[6], dots[7], dots[8], dots[9], dt, beta, gamma, alpha, contact, weighted)
        if alpha != 0.0:
            for j in range(n):
                force_prev[j] = 0.0
            for i in range(q):
                for kk in range(na):
                    j = idx[i, kk]
                    if j >= 0:
                        force_prev[j] += rv[i, 0, kk] * weighted[i]
        _record(step, q, elems, contact, vstate, lifted, counters, out_contact, out_body_u, out_body_a, out_on)
        for s_ in range(sens_idx.shape[0]):
            src = d if sens_kind[s_] == 0 else (v if sens_kind[s_] == 1 else a)
            acc_ = 0.0
            for k in range(sens_idx.shape[1]):
                j = sens_idx[s_, k]
                if j >= 0:
                    acc_ += sens_vals[s_, k] * src[j]
            out_sens[step, s_] = acc_


@njit(cache=True)
def _record(step, q, elems, contact, vstate, lifted, counters, out_contact, out_body_u, out_body_a, out_on):
    for i in range(q):
        on = elems[i] >= 0
        out_on[step, i] = on
        out_contact[step, i] = contact[i] if on else 0.0
        out_body_u[step, i] = vstate[0, i]
        out_body_a[step, i] = vstate[2, i]
        now = on and contact[i] < 0.0
        if now:
            counters[1] += 1
            if not lifted[i]:
                counters[0] += 1
        lifted[i] = now


# ------------------------------------------------------------ modal basis
@njit(cache=True, nogil=True)
def modal_block(phi, c_diag, k_diag, a_inv,
                nodes_x, cw, ct, y_s, length,
                dt, beta, gamma, alpha,
                d, v, a, force_prev,
                kind, m_v, m_w, k_v, c_v, k_t, c_t, weight,
                vstate, lifted, X, V, ACC, Y, R, RX,
                sens_rows, sens_kind,
                out_sens, out_contact, out_body_u, out_body_a, out_on, counters):
    """Advance K steps on a truncated modal basis (diagonal effective matrix).

    Written as explicit loops: the matrices are tiny (q vehicles x m modes), so
    library calls would cost more than their arithmetic.
    """
    m = d.shape[0]
    q = kind.shape[0]
    n_steps = X.shape[0]
    ca = 1.0 + alpha
    b2 = beta * dt * dt
    g1 = gamma * dt
    contact = np.empty(q)
    weighted = np.empty(q)
    n0 = np.zeros((q, m))
    n1 = np.zeros((q, m))
    n2 = np.zeros((q, m))
    p = np.zeros((q, m))
    z_u = np.empty((q, m))
    d_star = np.empty(m)
    v_star = np.empty(m)
    rhs = np.empty(m)
    z_b = np.empty(m)
    dots = np.zeros((10, q))
    S = np.empty((q, q))
    pz = np.empty(q)
    for step in range(n_steps):
        for j in range(m):
            d_star[j] = d[j] + dt * v[j] + (0.5 - beta) * dt * dt * a[j]
            v_star[j] = v[j] + (1.0 - gamma) * dt * a[j]
            rhs[j] = -ca * (c_diag[j] * v_star[j] + k_diag[j] * d_star[j])
            if alpha != 0.0:
                rhs[j] += alpha * (c_diag[j] * v[j] + k_diag[j] * d[j] - force_prev[j])
        elems, vals = contact_rows(X[step], Y, nodes_x, cw, ct, y_s, length)
        for i in range(q):
            for j in range(m):
                n0[i, j] = 0.0
                n1[i, j] = 0.0
                n2[i, j] = 0.0
            e = elems[i]
            if e < 0:
                continue
            for k in _ACTIVE:
                dof = 7 * e + k
                c0_, c1_, c2_ = vals[i, 0, k], vals[i, 1, k], vals[i, 2, k]
                for j in range(m):
                    ph = phi[dof, j]
                    n0[i, j] += c0_ * ph
                    n1[i, j] += c1_ * ph
                    n2[i, j] += c2_ * ph
        for i in range(q):
            s0 = s1 = s2 = s3 = s4 = 0.0
            for j in range(m):
                s0 += n0[i, j] * d_star[j]
                s1 += n1[i, j] * d_star[j]
                s2 += n0[i, j] * v_star[j]
                s3 += n2[i, j] * d_star[j]
                s4 += n1[i, j] * v_star[j]
            dots[0, i], dots[1, i], dots[2, i], dots[3, i], dots[4, i] = s0, s1, s2, s3, s4
        e0, c0, c1, c2, pred, aux = vehicle_coefficients(
            kind, m_v, m_w, k_v, c_v, k_t, c_t, weight, vstate, V[step], ACC[step], R[step], RX[step],
            dots[0], dots[1], dots[2], dots[3], dots[4], dt, beta, gamma, alpha)
        for i in range(q):
            for j in range(m):
                rhs[j] += n0[i, j] * e0[i]
                p[i, j] = c0[i] * n0[i, j] + c1[i] * n1[i, j] + c2[i] * n2[i, j]
        for j in range(m):
            z_b[j] = rhs[j] * a_inv[j]
        if q > 0:
            # Woodbury on the diagonal A: S = I + P A^-1 U^T.
            for k in range(q):
                for j in range(m):
                    z_u[k, j] = a_inv[j] * n0[k, j]
            for i in range(q):
                s = 0.0
                for j in range(m):
                    s += p[i, j] * z_b[j]
                pz[i] = s
                for k in range(q):
                    s = 1.0 if i == k else 0.0
                    for j in range(m):
                        s += p[i, j] * z_u[k, j]
                    S[i, k] = s
            sol = np.linalg.solve(S, pz)
            for j in range(m):
                corr = 0.0
                for k in range(q):
                    corr += n0[k, j] * sol[k]
                z_b[j] -= a_inv[j] * corr
        counters[2] += 1
        if not _newmark_update(d, v, a, d_star, v_star, z_b, b2, g1):
            counters[3] = step + 1
            return
        for i in range(q):
            s0 = s1 = s2 = s3 = s4 = s5 = 0.0
            for j in range(m):
                s0 += n0[i, j] * a[j]
                s1 += n1[i, j] * a[j]
                s2 += n2[i, j] * a[j]
                s3 += n0[i, j] * d[j]
                s4 += n0[i, j] * v[j]
                s5 += n1[i, j] * d[j]
            dots[5, i], dots[6, i], dots[7, i], dots[8, i] = s0, s1, s2, s3
            dots[9, i] = s4 + V[step, i] * s5
        vehicle_update(kind, m_v, m_w, k_v, c_v, k_t, c_t, weight, vstate, V[step], ACC[step], pred, aux,
                       dots[5], dots[6], dots[7], dots[8], dots[9], dt, beta, gamma, alpha, contact, weighted)
        for j in range(m):
            s = 0.0
            for i in range(q):
                s += n0[i, j] * weighted[i]
            force_prev[j] = s
        _record(step, q, elems, contact, vstate, lifted, counters, out_contact, out_body_u, out_body_a, out_on)
        for s_ in range(sens_rows.shape[0]):
            src = d if sens_kind[s_] == 0 else (v if sens_kind[s_] == 1 else a)
            acc_ = 0.0
            for j in range(m):
                acc_ += sens_rows[s_, j] * src[j]
            out_sens[step, s_] = acc_
