"""Spatial order of rodmol's static equilibrium against an independent continuum reference.

The reference solves the static Cosserat rod as a boundary value problem with
``scipy.integrate.solve_bvp`` (relative tolerance 1e-10; 1e-6 in the smoke run). It shares no code
with rodmol's discretisation: it reads only the model's parameters (radius
profile, stiffness diagonals, densities, gravity, cable offsets, anchors and
tensions, base pose).

Unknowns along s (global frame): the centreline u, the orientation as a unit
quaternion Q (R(Q) maps local to global), and the TOTAL stress resultants n, m
(body plus the cables' actuation stress, so that the cable's distributed and
anchor loads are internal and drop out):

    u' = R q,   Q' = Q (x) (0, k) / 2,   n' = -f,   m' = -u' x n,

with f = (rho - rho_medium) A(s) G the net weight density. The local strains
are recovered from the local total stress R^T n, R^T m by Newton's method on

    R^T n = Kl (q - q*) + sum_c T_c tau_c,   R^T m = Kth k + sum_c p_c x T_c tau_c,
    tau_c = (q + k x p_c) / |q + k x p_c|,

the sum running over the cables whose anchor lies beyond s. Boundary
conditions: the base pose at s = 0, n = m = 0 at s = L. Anchors inside the
rod split [0, L] into segments, each mapped onto [0, 1] and stacked into one
system with continuity of all states at the joints (the total stress is
continuous across an anchor).

The study: the paper's arm (bending scenario) at t = 0 (weight and buoyancy in
water) and t = 1 s (cable 11 at 2 N), plus a control with cable 11's anchor
moved onto a node of every grid; both schemes, N = 25 ... 800 doubling
(--quick: to 200, --smoke: 8 ... 32). Errors relative to L: the tip
|u_N(L) - u(L)| and the largest node error; observed order log2(e(N)/e(2N)).

    python solvers/continuum.py [--quick | --smoke] [--out DIR]
"""

import os

import numpy as np
from scipy.integrate import solve_bvp

from rodmol.discretise.load_entries import load_scale
from rodmol.errors import ParameterError

SCRIPT = "continuum.py"
#: States per segment: u (3), Q (4), n (3), m (3).
STATES = 13


# --------------------------------------------------------------------------- rotations

def quaternion_matrix(quat):
    """R (..., 3, 3), local to global, of quaternions (..., 4) = (a, b, c, d),
    divided by |Q|^2 so that R stays orthogonal if |Q| drifts."""
    a, b, c, d = np.moveaxis(np.asarray(quat, dtype=float), -1, 0)
    f = 2.0 / (a * a + b * b + c * c + d * d)
    rows = [[1 - f * (c * c + d * d), f * (b * c - a * d), f * (b * d + a * c)],
            [f * (b * c + a * d), 1 - f * (b * b + d * d), f * (c * d - a * b)],
            [f * (b * d - a * c), f * (c * d + a * b), 1 - f * (b * b + c * c)]]
    return np.moveaxis(np.array(rows), (0, 1), (-2, -1))


def matrix_quaternion(r):
    """A unit quaternion of the rotation matrix ``r`` (3, 3) (largest-pivot formula)."""
    r = np.asarray(r, dtype=float)
    trace = np.trace(r)
    pivots = [trace, r[0, 0], r[1, 1], r[2, 2]]
    i = int(np.argmax(pivots))
    if i == 0:
        a = 0.5 * np.sqrt(1.0 + trace)
        quat = [a, (r[2, 1] - r[1, 2]) / (4 * a), (r[0, 2] - r[2, 0]) / (4 * a), (r[1, 0] - r[0, 1]) / (4 * a)]
    else:
        j, k = i % 3, (i + 1) % 3  # the cyclic successors of axis i - 1
        x = 0.5 * np.sqrt(1.0 + 2.0 * r[i - 1, i - 1] - trace)
        v = np.zeros(3)
        v[i - 1] = x
        v[j] = (r[j, i - 1] + r[i - 1, j]) / (4 * x)
        v[k] = (r[k, i - 1] + r[i - 1, k]) / (4 * x)
        quat = [(r[k, j] - r[j, k]) / (4 * x), *v]
    quat = np.array(quat)
    return quat / np.linalg.norm(quat)


def _cross(a, b):
    """Row-wise cross product of (m, 3) arrays (np.cross is slow on small rows)."""
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=1)


def _skew(p):
    return np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])


# --------------------------------------------------------------------------- strains from stress

def strains_from_stress(n_loc, m_loc, kl, kth, cables, iterations=30):
    """Local strains (q, k), each (m, 3), carrying the local total stress
    ``n_loc`` [N], ``m_loc`` [N m] (m, 3) on sections of stiffness ``kl``,
    ``kth`` (m, 3); ``cables`` is a list of (offset p (3,) [m], tension [N])
    acting on these sections. Newton's method, vectorised over the sections."""
    q_star = np.array([1.0, 0.0, 0.0])
    q = q_star + n_loc / kl
    k = m_loc / kth
    if not cables:
        return q, k
    eye = np.eye(3)
    for _ in range(iterations):
        res_n = kl * (q - q_star) - n_loc
        res_m = kth * k - m_loc
        jac = np.zeros((len(q), 6, 6))
        jac[:, [0, 1, 2], [0, 1, 2]] = kl
        jac[:, [3, 4, 5], [3, 4, 5]] = kth
        for p, tension in cables:
            c = q + _cross(k, np.broadcast_to(p, k.shape))
            length = np.linalg.norm(c, axis=1)
            tau = c / length[:, None]
            res_n += tension * tau
            res_m += tension * _cross(np.broadcast_to(p, tau.shape), tau)
            # d tau / d c = (I - tau tau^T) / |c|; dc/dq = I, dc/dk = -[p]x.
            dtau = tension * (eye - tau[:, :, None] * tau[:, None, :]) / length[:, None, None]
            px = _skew(p)
            jac[:, :3, :3] += dtau
            jac[:, :3, 3:] -= dtau @ px
            jac[:, 3:, :3] += px @ dtau
            jac[:, 3:, 3:] -= px @ dtau @ px
        res = np.hstack([res_n, res_m])
        step = np.linalg.solve(jac, -res[:, :, None])[:, :, 0]
        q, k = q + step[:, :3], k + step[:, 3:]
        if np.max(np.abs(step[:, :3])) < 1e-14 and np.max(np.abs(step[:, 3:]) / (1.0 + np.abs(k))) < 1e-14:
            break
    return q, k


# --------------------------------------------------------------------------- the boundary value problem

class _Problem:
    """The static rod on segments between anchors, in scaled variables:
    x in [0, 1] per segment, u / L, Q, n / F, m / (F L) with F a force scale."""

    def __init__(self, model, t):
        rod = model.rod
        self.model, self.length = model, rod.length
        tensions = model.tensions(t)
        self.cables = [(c.offset3, float(tc), float(c.anchor)) for c, tc in zip(model.cables, tensions)
                       if tc > 0.0]
        inner = sorted({a for _, _, a in self.cables if a < self.length * (1.0 - 1e-12)})
        self.joints = np.array([0.0, *inner, self.length])
        self.segments = len(self.joints) - 1
        net = (rod.material.rho - model.medium.rho)
        self.weight = lambda s: net * rod.area(s)[:, None] * model.gravity  # global [N/m]
        self.force = max(load_scale(model, t), 1e-300)
        self.u0 = np.asarray(model.base.position, dtype=float)
        self.quat0 = matrix_quaternion(model.base.rotation)

    def active(self, j):
        """(p, T) of the cables running over segment j."""
        return [(p, tension) for p, tension, anchor in self.cables if anchor > self.joints[j] + 1e-15]

    def arc(self, j, x):
        return self.joints[j] + (self.joints[j + 1] - self.joints[j]) * x

    def segment_rates(self, j, x, y, lam):
        """d/dx of the scaled states (13, m) of segment j at load factor ``lam``."""
        s, L, F = self.arc(j, x), self.length, self.force
        quat, n, m = y[3:7], y[7:10], y[10:13]
        r = quaternion_matrix(quat.T)  # (m, 3, 3)
        n_loc = F * np.einsum("kji,jk->ki", r, n)  # R^T n [N]
        m_loc = F * L * np.einsum("kji,jk->ki", r, m)
        kl, kth = self.model.rod.stiffness(s)
        cables = [(p, lam * tension) for p, tension in self.active(j)]
        q, k = strains_from_stress(n_loc, m_loc, kl, kth, cables)
        du = np.einsum("kij,kj->ik", r, q)  # R q, per unit s: dimensionless
        a, b, c, d = quat
        w = L * k.T  # k per unit of s / L
        dquat = 0.5 * np.array([-b * w[0] - c * w[1] - d * w[2], a * w[0] + c * w[2] - d * w[1],
                                a * w[1] + d * w[0] - b * w[2], a * w[2] + b * w[1] - c * w[0]])
        dn = -lam * L / F * self.weight(s).T
        dm = -_cross(du.T, n.T).T
        return (self.joints[j + 1] - self.joints[j]) / L * np.vstack([du, dquat, dn, dm])

    def rates(self, x, y, lam):
        return np.vstack([self.segment_rates(j, x, y[STATES * j:STATES * (j + 1)], lam)
                          for j in range(self.segments)])

    def boundary(self, ya, yb):
        parts = [ya[0:3] - self.u0 / self.length, ya[3:7] - self.quat0]
        for j in range(1, self.segments):
            parts.append(ya[STATES * j:STATES * (j + 1)] - yb[STATES * (j - 1):STATES * j])
        parts.append(yb[-6:])
        return np.concatenate(parts)

    def straight(self, x):
        """The unloaded rod: straight from the base pose, no stress."""
        y = np.zeros((STATES * self.segments, len(x)))
        axis = quaternion_matrix(self.quat0)[:, 0]
        for j in range(self.segments):
            s = self.arc(j, x)
            y[STATES * j:STATES * j + 3] = (self.u0[:, None] + axis[:, None] * s) / self.length
            y[STATES * j + 3:STATES * j + 7] = self.quat0[:, None]
        return y

    def evaluate(self, sol, s):
        """Positions (m, 3) [m] and rotations (m, 3, 3) at arc lengths ``s``."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        j = np.clip(np.searchsorted(self.joints, s, side="right") - 1, 0, self.segments - 1)
        x = (s - self.joints[j]) / (self.joints[j + 1] - self.joints[j])
        y = sol.sol(np.clip(x, 0.0, 1.0))
        rows = STATES * j[None, :] + np.arange(7)[:, None]
        z = y[rows, np.arange(len(s))[None, :]]
        return self.length * z[:3].T, quaternion_matrix(z[3:7].T)


def continuum_equilibrium(model, t=0.0, s=None, tol=1e-10, max_nodes=300000):
    """Static equilibrium of ``model`` at time ``t`` as a continuum rod.

    Gravity and buoyancy, and the cable tensions ``model.tensions(t)`` act;
    the base pose is ``model.base``'s. External loads (``model.loads``) are
    not supported.

    Parameters
    ----------
    model : rodmol.Model
        Only its parameters are read; its grid size plays no role.
    t : float
        Time [s] at which the tensions are read.
    s : array_like, optional
        Arc lengths [m] of the output; default the model's nodes.
    tol : float
        ``solve_bvp``'s relative tolerance of the final solve.

    Returns
    -------
    dict
        ``s`` (m,) [m]; ``positions`` (m, 3) [m], global; ``rotations``
        (m, 3, 3), local to global; ``at``: a function of arc lengths
        returning (positions, rotations) anywhere on [0, L]; ``nodes``: the
        size of the final collocation mesh.
    """
    if model.loads:
        raise ParameterError("continuum_equilibrium: external `loads` are not supported, got "
                             f"{len(model.loads)} load(s)")
    problem = _Problem(model, t)
    x = np.linspace(0.0, 1.0, 41)
    y = problem.straight(x)
    # Load continuation at a loose tolerance, then the final solve.
    lam, step, sol = 0.0, 1.0, None
    while lam < 1.0:
        target = min(1.0, lam + step)
        trial = solve_bvp(lambda x, y, lam=target: problem.rates(x, y, lam), problem.boundary, x, y,
                          tol=1e-6, max_nodes=max_nodes)
        if trial.status == 0:
            sol, lam, step = trial, target, min(1.0, 2.0 * step)
            x, y = trial.x, trial.y
        else:
            step *= 0.5
            if step < 1e-3:
                raise RuntimeError(f"continuum equilibrium: no solution beyond load factor {lam:.4g}: "
                                   f"{trial.message}")
    sol = solve_bvp(lambda x, y: problem.rates(x, y, 1.0), problem.boundary, x, y, tol=tol,
                    max_nodes=max_nodes)
    if sol.status != 0:
        raise RuntimeError(f"continuum equilibrium: {sol.message}")
    s = model.s_nodes if s is None else np.asarray(s, dtype=float)
    positions, rots = problem.evaluate(sol, s)
    return dict(s=s, positions=positions, rotations=rots, nodes=len(sol.x),
                at=lambda s_out: problem.evaluate(sol, s_out))


# --------------------------------------------------------------------------- the study

def discrete_positions(model, t, scheme):
    """rodmol's equilibrium node positions (N+1, 3) [m], rebuilt from the strains."""
    from rodmol.discretise.system import SemiDiscrete
    from rodmol.result import from_states
    from rodmol.solve.equilibrium import equilibrium

    system = SemiDiscrete(model, scheme)
    y = equilibrium(system, t)
    return from_states(system, np.array([t]), y[None], True, "", {}).positions[0]


def observed_orders(errors):
    """log2(e(N) / e(2N)) for successive doublings."""
    e = np.asarray(errors, dtype=float)
    return list(np.log2(e[:-1] / e[1:]))


def fitted_order(sizes, errors):
    """Least-squares slope of -log e against log N."""
    return float(-np.polyfit(np.log(sizes), np.log(errors), 1)[0])


def _cases(rodmol, sizes):
    """(t, label, model(N)) of the study: the bending scenario at rest and
    pulled, and a control with cable 11's anchor moved onto a node of every grid."""
    scenario = rodmol.scenarios.get("bending")
    L = rodmol.arm.LENGTH
    on_node = 0.76 * L  # 0.76 N is an integer for N = 25 * 2^j

    def moved(n):
        cable = rodmol.Cable(rodmol.arm.CABLE_OFFSETS[11], on_node, scenario.tensions[11], name="cable 11")
        return rodmol.Model(rodmol.arm.paper_rod(), n, medium="water", cables=[cable])

    anchor = rodmol.arm.cable_anchor(11)
    return [(0.0, "gravity and buoyancy (water)", scenario.model, anchor),
            (1.0, f"cable 11 at 2 N, anchor L3 = {anchor} m", scenario.model, anchor),
            (1.0, f"control: cable 11 at 2 N, anchor moved to 0.76 L = {on_node:.5f} m", moved, on_node)]


def main(argv=None):
    import _common as C
    from _common import plt, rodmol

    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    sizes = C.pick(args, [25, 50, 100, 200, 400, 800], [25, 50, 100, 200], [8, 16, 32])
    # The smoke run's errors are 1e-4 L and more; its reference moves by ~1e-8 L from tol 1e-6 to 1e-8.
    tol = C.pick(args, 1e-10, 1e-10, 1e-6)
    L = rodmol.arm.LENGTH
    cases = _cases(rodmol, sizes)
    rows, summary, checks = [], [], []
    for case, (t, label, make, anchor) in enumerate(cases):
        with C.Stopwatch() as sw:
            ref = continuum_equilibrium(make(sizes[0]), t, tol=tol)
        loose = continuum_equilibrium(make(sizes[0]), t, tol=100 * tol)
        drift = float(np.max(np.linalg.norm(loose["positions"] - ref["positions"], axis=1)) / L)
        checks.append(f"case {case} ({label}, t = {t:g} s): {ref['nodes']} mesh nodes, {sw.seconds:.1f} s; "
                      f"nodes move by {drift:.1e} L between tol {100 * tol:.0e} and {tol:.0e}")
        print(checks[-1], flush=True)
        for scheme, nominal in (("upwind", 1), ("centred", 2)):
            tips, maxima = [], []
            for n in sizes:
                model = make(n)
                with C.Stopwatch() as sw_eq:
                    pos = discrete_positions(model, t, scheme)
                exact, _ = ref["at"](model.s_nodes)
                err = np.linalg.norm(pos - exact, axis=1) / L
                tips.append(float(err[-1]))
                maxima.append(float(err.max()))
                rows.append(dict(case=case, t_s=t, scheme=scheme, N=n, anchor_in_cell=(anchor / model.ds) % 1.0,
                                 tip_error=tips[-1], max_node_error=maxima[-1],
                                 tip_error_x_N_p=tips[-1] * float(n) ** nominal, equilibrium_s=sw_eq.seconds))
                print(f"  {scheme} N={n}: tip error {tips[-1]:.3e} L, max {maxima[-1]:.3e} L", flush=True)
            for row, p_tip, p_max in zip(rows[-len(sizes):], observed_orders(tips) + [np.nan],
                                         observed_orders(maxima) + [np.nan]):
                row["tip_order"], row["max_order"] = float(p_tip), float(p_max)
            summary.append(dict(case=case, description=label, scheme=scheme,
                                fitted_tip_order=fitted_order(sizes, tips),
                                fitted_max_order=fitted_order(sizes, maxima)))

    base = os.path.join(args.out, "continuum")
    note = ("paper's arm; errors |u_N - u| / L of rodmol's equilibrium (positions rebuilt from the strains) "
            f"against the continuum reference (solve_bvp, tol {tol:.0e}), at the tip and the largest over the "
            "nodes; 'order' at N is log2(e(N) / e(2N)); tip_error_x_N_p is e N^p with p the scheme's "
            "nominal order (1 upwind, 2 centred); anchor_in_cell: where the cable's anchor lies inside "
            "its cell (0 = on a node)")
    C.write_csv(base + ".csv", rows, header + checks + [note])

    fig, axes = plt.subplots(1, len(cases), figsize=(15, 4.5), sharey=True)
    ns = np.array(sizes, float)
    for case, (ax, (t, label, _, _)) in enumerate(zip(axes, cases)):
        for scheme, mark, p in (("upwind", "o", 1), ("centred", "s", 2)):
            sel = [r for r in rows if r["case"] == case and r["scheme"] == scheme]
            ax.loglog(ns, [r["tip_error"] for r in sel], mark + "-", label=f"{scheme}: tip")
            ax.loglog(ns, [r["max_node_error"] for r in sel], mark + "--", alpha=0.6, label=f"{scheme}: max node")
            ax.loglog(ns, sel[0]["tip_error"] * (ns[0] / ns) ** p, ":", color="grey",
                      label="O(1/N)" if p == 1 else "O(1/N^2)")
        C.n_axis(ax, ns)
        ax.set_xlabel("elements N")
        ax.set_title(f"{case}: t = {t:g} s, {label}", fontsize=8)
    axes[0].set_ylabel("error / L vs continuum (solve_bvp)")
    axes[0].legend(fontsize=7)
    C.save_figure(fig, base + ".png")

    fmt = {"anchor_in_cell": ".3f", "tip_error": ".3e", "max_node_error": ".3e", "tip_error_x_N_p": ".3g",
           "tip_order": ".3f", "max_order": ".3f", "equilibrium_s": ".2f"}
    sections = [
        ("Reference", "\n".join(f"- {c}" for c in checks) + "\n"),
        ("Results", note + "\n\n" + C.markdown_table(rows, None, fmt)),
        ("Fitted orders", "Least-squares slope of log e against log N over all N:\n\n"
         + C.markdown_table(summary, None, {"fitted_tip_order": ".3f", "fitted_max_order": ".3f"})
         + "\nWith the cable anchored at L3 (case 1) the centred scheme's successive orders scatter "
           "around 2 while e N^2 stays bounded: the anchor falls at a different place inside its cell on "
           "each grid, and the cell holding the jump of the actuation stress adds an O(ds^2) error whose "
           "constant depends on that place. With the anchor on a node of every grid (case 2) the "
           "order is 2 at every doubling.\n"),
        ("Figure", f"![continuum]({os.path.basename(base)}.png)\n"),
    ]
    C.write_markdown(base + ".md", "Spatial order against a continuum reference", header, sections)
    print("wrote", base + ".{csv,md,png}")


if __name__ == "__main__":
    main()
