"""Till's discretisation of a tendon robot, written independently (numba).

The scheme of Till, Aloi and Rucker (IJRR 2019) as his C++ example
``02_Dynamics/03_Tendon_Robot`` applies it: the time derivatives are replaced
by the BDF-alpha formula at a fixed step dt,

    y_t(t_n) = c0 y(t_n) + h_n,   h_n = c1 y_{n-1} + c2 y_{n-2} + d1 y_t(t_{n-1}),
    c0 = (1.5 + a) / (dt (1 + a)),  c1 = -2 / dt,  c2 = (0.5 + a) / (dt (1 + a)),
    d1 = a / (1 + a)                (a = alpha; a = 0 is BDF2),

which leaves, at each step, a boundary value problem in s. It is solved by
shooting with forward Euler in s on N equally spaced points: unknowns are the
backbone's base internal force n(0) (body frame), base curvature u(0) and the
tendon tension; residuals are the force and moment balance of the tip plate
(the tendon terminates there) and the tendon's length law with slack,

    path + base_to_motor + slack = l* (1 + compliance tension),  l* = rest + z(t).

Everything is in Till's frame: rod axis +z, body-frame vectors v (shear and
stretch), u (curvature), q (velocity), w (angular velocity); the tendon at the
body-frame offset r. The constitutive law is Kelvin-Voigt,
n = Kse (v - e3) + Bse v_t, m = Kbt u + Bbt u_t, the drag C q|q| per body
component, gravity g global. Setting c0 = 0 and h = 0 gives the statics
(q = w = 0 then stays zero along s).

Per point the state holds p (3, global), R (9, row-major, body to global),
v, u, q, w (3 each, body) and the integrated tendon length (1); the
time-differentiated fields are z = (v, u, q, w, v_s, u_s) (18).
"""

import numpy as np
from numba import njit

# Indices of the parameter vector P (built by till_reference.parameters).
KSE, KBT, BSE, BBT, CDRAG, RHOJ, GRAV, OFFSET = 0, 3, 6, 9, 12, 15, 18, 21
RHOA, DS, COMPLIANCE, REST, BASE_TO_MOTOR, FSCALE, LENGTH = 24, 25, 26, 27, 28, 29, 30
N_PARAMS = 31
N_Y, N_Z = 25, 18


@njit(cache=True)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def _matmul(A, B, out):
    """out = A B for small matrices (loops: no BLAS, which compiles slowly)."""
    for i in range(A.shape[0]):
        for j in range(B.shape[1]):
            acc = 0.0
            for k in range(A.shape[1]):
                acc += A[i, k] * B[k, j]
            out[i, j] = acc


@njit(cache=True)
def _matvec(A, x, out):
    for i in range(A.shape[0]):
        acc = 0.0
        for k in range(A.shape[1]):
            acc += A[i, k] * x[k]
        out[i] = acc


@njit(cache=True)
def _solve(M, rhs):
    """M^{-1} rhs by Gaussian elimination with partial pivoting (small systems)."""
    n = M.shape[0]
    A, b = M.copy(), rhs.copy()
    for k in range(n):
        p = k + np.argmax(np.abs(A[k:, k]))
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            b[k], b[p] = b[p], b[k]
        for i in range(k + 1, n):
            f = A[i, k] / A[k, k]
            for j in range(k, n):
                A[i, j] -= f * A[k, j]
            b[i] -= f * b[k]
    out = np.zeros(n)
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= A[i, j] * out[j]
        out[i] = acc / A[i, i]
    return out


@njit(cache=True)
def shoot(x, P, zh, c0, z_motor, n, Y, Z):
    """Integrate from the base guess x = (n(0) (3, body) [N], u(0) (3) [1/m],
    tension-or-minus-slack [N]) along n points; fill Y (n, 25) and Z (n, 18);
    return the tip residuals (force [N], moment [N m], length [m]), scaled."""
    r = P[OFFSET:OFFSET + 3]
    tension, slack = max(x[6], 0.0), max(-x[6], 0.0)
    Y[0, :] = 0.0
    Y[0, 3], Y[0, 7], Y[0, 11] = 1.0, 1.0, 1.0
    for k in range(3):
        Y[0, 12 + k] = x[k] / P[KSE + k]
        Y[0, 15 + k] = x[3 + k]
    Y[0, 14] += 1.0
    Y[0, 24] = P[BASE_TO_MOTOR]
    ds = P[DS]
    rhoa = P[RHOA]
    K = np.zeros((6, 6))
    rhs = np.zeros(6)
    pb, at, gb, t1, t2, t3, nb, mb = (np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3),
                                      np.zeros(3), np.zeros(3))
    A, hr, G, H = np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((3, 3))
    hr[0, 1], hr[0, 2], hr[1, 0], hr[1, 2], hr[2, 0], hr[2, 1] = -r[2], r[1], r[2], -r[0], -r[1], r[0]
    dy = np.zeros(N_Y)
    for i in range(n):
        y, h = Y[i], zh[i]
        R = y[3:12].reshape((3, 3))
        v, u, q, w = y[12:15], y[15:18], y[18:21], y[21:24]
        vt, ut, qt, wt = c0 * v + h[0:3], c0 * u + h[3:6], c0 * q + h[6:9], c0 * w + h[9:12]
        _cross(u, r, pb)
        pb += v
        npb = np.sqrt(pb[0] ** 2 + pb[1] ** 2 + pb[2] ** 2)
        # Tendon: A = tension (I - t t^T) / |p_s|, with t the tendon's unit tangent (body frame).
        for a in range(3):
            for b in range(3):
                A[a, b] = tension * ((1.0 if a == b else 0.0) - pb[a] * pb[b] / npb**2) / npb
        _matmul(A, hr, G)
        G *= -1.0
        _matmul(hr, G, H)
        _cross(u, pb, t1)
        _matvec(A, t1, at)  # the tendon's distributed force term a
        for k in range(3):
            nb[k] = P[KSE + k] * (v[k] - (1.0 if k == 2 else 0.0)) + P[BSE + k] * vt[k]
            mb[k] = P[KBT + k] * u[k] + P[BBT + k] * ut[k]
        K[:3, :3] = A
        K[:3, 3:] = G
        K[3:, :3] = G.T
        K[3:, 3:] = H
        for k in range(3):
            K[k, k] += P[KSE + k] + c0 * P[BSE + k]
            K[3 + k, 3 + k] += P[KBT + k] + c0 * P[BBT + k]
        _matvec(R.T, P[GRAV:GRAV + 3], gb)
        _cross(w, q, t1)
        _cross(u, nb, t2)
        for k in range(3):
            rhs[k] = (-at[k] + rhoa * (t1[k] + qt[k]) + P[CDRAG + k] * q[k] * abs(q[k])
                      - rhoa * gb[k] - t2[k] - P[BSE + k] * h[12 + k])
        _cross(r, at, t1)
        for k in range(3):
            t3[k] = P[RHOJ + k] * w[k]
        _cross(w, t3, t2)
        for k in range(3):
            rhs[3 + k] = -t1[k] + t2[k] + P[RHOJ + k] * wt[k] - P[BBT + k] * h[15 + k]
        _cross(v, nb, t1)
        _cross(u, mb, t2)
        for k in range(3):
            rhs[3 + k] -= t1[k] + t2[k]
        sol = _solve(K, rhs)
        Z[i, 0:3], Z[i, 3:6], Z[i, 6:9], Z[i, 9:12], Z[i, 12:18] = v, u, q, w, sol
        if i == n - 1:
            break
        _matvec(R, v, t1)
        dy[0:3] = t1
        for a in range(3):  # R_s = R hat(u)
            dy[3 + 3 * a + 0] = R[a, 1] * u[2] - R[a, 2] * u[1]
            dy[3 + 3 * a + 1] = R[a, 2] * u[0] - R[a, 0] * u[2]
            dy[3 + 3 * a + 2] = R[a, 0] * u[1] - R[a, 1] * u[0]
        dy[12:18] = sol
        _cross(u, q, t1)
        _cross(w, v, t2)
        dy[18:21] = vt - t1 + t2
        _cross(u, w, t1)
        dy[21:24] = ut - t1
        dy[24] = npb
        Y[i + 1] = y + ds * dy
    # Tip plate: the backbone's stress plus the tendon's pull -tension t balance.
    res = np.zeros(7)
    fb = -tension * pb / npb
    _cross(r, fb, t1)
    scale_m = P[FSCALE] * P[LENGTH]
    for k in range(3):
        res[k] = (fb[k] - nb[k]) / P[FSCALE]
        res[3 + k] = (t1[k] - mb[k]) / scale_m
    l_star = P[REST] + z_motor
    # Scaled by 1e-3 L, a path error of 7e-4 m per unit: the residual's
    # round-off (~1e-13 m in the path, from the shooting's amplification) stays
    # far below the tolerance, and 1e-7 of it is a tension error of 1e-6 N
    # (tendon stiffness 1 / (l C) = 1.3e4 N/m).
    res[6] = (Y[n - 1, 24] + slack - l_star * (1.0 + P[COMPLIANCE] * tension)) / (1e-3 * P[LENGTH])
    return res


@njit(cache=True)
def _jacobian(x, P, zh, c0, z_motor, n, Y, Z, steps):
    J = np.zeros((7, 7))
    for j in range(7):
        xp, xm = x.copy(), x.copy()
        xp[j] += steps[j]
        xm[j] -= steps[j]
        J[:, j] = (shoot(xp, P, zh, c0, z_motor, n, Y, Z) - shoot(xm, P, zh, c0, z_motor, n, Y, Z)) / (2 * steps[j])
    return J


@njit(cache=True)
def newton(x, J, P, zh, c0, z_motor, n, Y, Z, tol, steps, chord):
    """Newton's method with backtracking on |residual|_2. With ``chord`` J is
    reused (and refreshed in place when the residual falls by less than 5x in
    an iteration), else refreshed every iteration. Returns (x, iterations or
    -1, max |scaled residual|); Y, Z hold the shot of the returned x."""
    res = shoot(x, P, zh, c0, z_motor, n, Y, Z)
    norm = np.sqrt(np.sum(res**2))
    fresh = False
    for it in range(100):
        if np.max(np.abs(res)) < tol:
            return x, it, np.max(np.abs(res))
        if not chord and it > 0:
            J[:, :] = _jacobian(x, P, zh, c0, z_motor, n, Y, Z, steps)
        dx = _solve(J, res)
        lam = 1.0
        while True:
            trial = x - lam * dx
            new = shoot(trial, P, zh, c0, z_motor, n, Y, Z)
            new_norm = np.sqrt(np.sum(new**2))
            if new_norm < norm or lam < 1e-4:
                break
            lam *= 0.5
        slow = new_norm > 0.2 * norm
        x, res, norm = trial, new, new_norm
        if chord and slow and not fresh:
            J[:, :] = _jacobian(x, P, zh, c0, z_motor, n, Y, Z, steps)
            res = shoot(x, P, zh, c0, z_motor, n, Y, Z)
            fresh = True
        else:
            fresh = False
    return x, -1, np.max(np.abs(res))


@njit(cache=True)
def statics(x0, P, n, z_motor, tol, steps):
    """The static equilibrium with the motor at z_motor: (x, iterations, residual)."""
    Y, Z, zh = np.zeros((n, N_Y)), np.zeros((n, N_Z)), np.zeros((n, N_Z))
    J = _jacobian(x0, P, zh, 0.0, z_motor, n, Y, Z, steps)
    return newton(x0.copy(), J, P, zh, 0.0, z_motor, n, Y, Z, tol, steps, False)


@njit(cache=True)
def march(x_static, P, n, dt, alpha, t_knots, z_knots, n_steps, tol, steps):
    """n_steps BDF-alpha steps from the static equilibrium x_static (at rest
    for all t < 0); the solve of step i uses the motor at t_i = i dt (Till's
    loop). Returns (tip (n_steps, 3) global [m], tension (n_steps,) [N],
    iterations (n_steps,; -1 where the shooting failed, which ends the run),
    worst scaled residual)."""
    Y, Z = np.zeros((n, N_Y)), np.zeros((n, N_Z))
    zh = np.zeros((n, N_Z))
    x = x_static.copy()
    shoot(x, P, zh, 0.0, np.interp(0.0, t_knots, z_knots), n, Y, Z)
    c0 = (1.5 + alpha) / (dt * (1.0 + alpha))
    c1 = -2.0 / dt
    c2 = (0.5 + alpha) / (dt * (1.0 + alpha))
    d1 = alpha / (1.0 + alpha)
    # At rest before t = 0: y_{-1} = y_{-2} = y_static and y_t = 0.
    z_old = Z.copy()
    zh = (c1 + c2) * Z
    J = _jacobian(x, P, zh, c0, z_knots[0], n, Y, Z, steps)
    tip, tension, iterations = np.zeros((n_steps, 3)), np.zeros(n_steps), np.zeros(n_steps, dtype=np.int64)
    x_prev = x.copy()
    worst = 0.0
    for i in range(n_steps):
        guess = 2.0 * x - x_prev  # linear predictor
        x_prev = x.copy()
        x, its, err = newton(guess, J, P, zh, c0, np.interp(i * dt, t_knots, z_knots), n, Y, Z, tol, steps, True)
        worst = max(worst, err)
        iterations[i] = its
        tip[i] = Y[n - 1, 0:3]
        tension[i] = max(x[6], 0.0)
        if its < 0:
            return tip[:i + 1], tension[:i + 1], iterations[:i + 1], worst
        zt = c0 * Z + zh  # y_t at this step (needed by alpha != 0)
        zh = c1 * Z + c2 * z_old + d1 * zt
        z_old = Z.copy()
    return tip, tension, iterations, worst
