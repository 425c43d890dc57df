"""The assembled system of rods and bodies (rodmol.discretise.assembly): its
composed layout and Jacobian pattern."""

import numpy as np
import pytest
from newton_check import NewtonCheck

import rodmol
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.rigid import NET_MASS, NET_MOMENT


def _system():
    mat = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Rod(0.2, radius=0.01, material=mat)
    arm = rodmol.Model(rod, 4, cables=[rodmol.Cable((0.005, 0.0), 0.2, tension=0.1)])
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), centre_of_mass=(0.0, 0.004, 0.0), volume=2e-5,
                            drag=(1, 2, 3, 0.1, 0.2, 0.3), added_mass=(0.01, 0.02, 0.03, 0, 0, 0))
    plate = rodmol.RigidBody(0.5, (1e-3, 1e-3, 1e-3), motion="fixed", position=(1.0, 0.0, 0.0))
    # Penalty joints: a's tip clamped to a free payload, b's tip pinned to a fixed post, a node of c pinned
    # to the world and its middle clamped to d's tip.
    payload = rodmol.RigidBody(0.02, (1e-6, 2e-6, 3e-6), position=(0.21, 0.0, 0.0), centre_of_mass=(0.01, 0, 0))
    post = rodmol.RigidBody(0.5, (1e-3, 1e-3, 1e-3), motion="fixed", position=(-0.22, 0.0, 0.0))
    joints = [rodmol.Joint(("head", (0.02, 0.0, 0.0)), ("a", "base")),
              rodmol.Joint(("head", (-0.02, 0.0, 0.0), np.diag([-1.0, -1.0, 1.0])), ("b", "base")),
              rodmol.Joint(("plate", (0.0, 0.0, 0.0)), ("c", "base")),
              rodmol.Joint(("payload", (0.01, 0.0, 0.0)), ("a", "tip")),
              rodmol.Joint(("post", (0.0, 0.0, 0.0)), ("b", "tip"), kind="pin"),
              rodmol.Joint("world", ("c", 0.05), kind="pin"),
              rodmol.Joint(("d", "tip"), ("c", 0.1))]  # d rises from the world to c's middle
    rise = rodmol.BaseMotion(position=(1.1, -0.2, 0.0), rotation=((0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    return rodmol.System({"a": arm, "b": arm, "c": arm, "d": arm.replace(base=rise)},
                         {"head": head, "plate": plate, "payload": payload, "post": post}, joints,
                         medium="water", gravity=(0.0, 0.0, -9.81))


def test_parts_tile_the_state_in_order():
    assembly = Assembly(_system())
    rod_size = assembly.rods["a"].size
    spans = [(s.start, s.stop) for s in assembly.parts.values()]
    bodies = np.cumsum([4 * rod_size, 13, 7, 13, 7])
    assert spans == [(k * rod_size, (k + 1) * rod_size) for k in range(4)] + list(zip(bodies[:-1], bodies[1:]))
    assert assembly.size == bodies[-1] == len(assembly.atol_scale())


def test_pattern_holds_every_nonzero_of_a_difference_jacobian():
    assembly = Assembly(_system())
    rng = np.random.default_rng(3)
    y = assembly.undeformed_state()
    y += 1e-2 * rng.standard_normal(assembly.size) * assembly.atol_scale()
    f0 = assembly(0.0, y)
    pattern = assembly.pattern().toarray()
    touched = np.zeros_like(pattern)
    for j in range(assembly.size):
        step = 1e-6 * assembly.atol_scale()[j]
        z = y.copy()
        z[j] += step
        touched[:, j] = assembly(0.0, z) != f0
    missing = np.argwhere(touched & ~pattern)
    assert missing.size == 0, f"entries outside the pattern: {missing[:5].tolist()}"
    head = assembly.bodies["head"].fields
    first = assembly.parts["a"].start + assembly.rods["a"].layout.header
    assert touched[head["w"].start, first:first + 19].any()  # the rod pulls on the head
    assert touched[first:first + 19, head["v"].start].any()  # the head carries the rod
    plate = assembly.bodies["plate"].fields
    assert not pattern[:, plate["x"]].any() and not pattern[plate["x"]].any()  # a fixed body stays
    # The penalty joints: a's tip and the payload read each other; b's tip reads the post's pose.
    payload, post = assembly.bodies["payload"].fields, assembly.bodies["post"].fields
    tip_a = assembly.parts["a"].stop - assembly.rods["a"].layout.block
    tip_b = assembly.parts["b"].stop - assembly.rods["b"].layout.block
    assert touched[payload["v"].start:payload["w"].stop, tip_a:tip_a + 19].any()
    assert touched[tip_a:tip_a + 19, payload["x"].start:payload["w"].stop].any()
    assert touched[tip_b:tip_b + 19, post["x"].start:post["Q"].stop].any()
    tip_d = assembly.parts["d"].stop - assembly.rods["d"].layout.block
    middle_c = assembly.parts["c"].start + assembly.rods["c"].layout.header + assembly.rods["c"].layout.block
    assert touched[tip_d:tip_d + 19, middle_c:middle_c + 19].any() and touched[middle_c:middle_c + 19, tip_d:tip_d + 19].any()


def test_schur_preconditioner_inverts_the_newton_matrix_of_a_loop():
    # Two arms from the world to one free bar, a ring on one arm's middle (bases on the world: no tree
    # coupling is left out), the bar and the ring free bodies with penalty joints: the rods' exact blocks, the bar's block and the joints' blocks
    # are all kept, so the preconditioner is the Newton matrix I - gamma J itself, to the error of its
    # forward differences (on the joints' stiff terms: 3.5e-4 of each entry's scale here, 1e-4 with the
    # joints 4 times softer, 1e-9 without joints); without the joints' blocks (rods and bar each on
    # their own) it is off by 100 times that (measured 8e7 times).
    mat = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Rod(0.2, radius=0.01, material=mat)
    arms = {name: rodmol.Model(rod, 4, base=rodmol.BaseMotion(position=(0.0, y, 0.0))) for name, y in
            (("a", 0.0), ("b", 0.04))}
    bar = rodmol.RigidBody(0.02, (1e-5, 1e-5, 1e-5), position=(0.2, 0.0, 0.0), centre_of_mass=(0.0, 0.02, 0.0))
    ring = rodmol.RigidBody(0.01, (1e-6, 1e-6, 1e-6), position=(0.1, 0.0, 0.0))  # on a's middle: S couples bodies
    joints = [rodmol.Joint(("bar", (0.0, 0.0, 0.0)), ("a", "tip")),
              rodmol.Joint(("bar", (0.0, 0.04, 0.0)), ("b", "tip"), kind="pin"),
              rodmol.Joint(("ring", (0.0, 0.0, 0.0)), ("a", 0.1), kind="pin")]
    check, gamma = NewtonCheck(Assembly(rodmol.System(arms, {"bar": bar, "ring": ring}, joints,
                                                     gravity=(0.0, -9.81, 0.0)))), 1e-4
    precond = check.preconditioner(gamma)
    assert precond.coupled == [check.assembly.bodies["bar"], check.assembly.bodies["ring"]]
    v = np.random.default_rng(6).standard_normal(check.assembly.size) * check.scale
    r = check.newton(gamma) @ v
    error = check.error(check.solve(precond, r, gamma), v)
    assert error < 1e-3
    assert check.error(check.apart(precond, r, gamma), v) > 100 * error


def test_a_free_body_carries_the_base_half_cell_of_each_rod_clamped_to_it():
    """The head carries the half cell (ds/2, centred) of arms a and b next to
    it, lumped at their clamps: its mass matrix gains their kinetic energy
    1/2 (v_p Rj M Rj^T v_p + w Rj J Rj^T w), v_p = v + w x p, with the
    section's mass (rho A, plus the water's 1.5 rho_w A across the rod) and
    rotational inertia rho (2I, I, I); its net weight gains (rho - rho_w) A
    ds/2 at each clamp. The upwind scheme's nodes stand for the whole rod:
    the body carries nothing."""
    system = _system()
    head, part = system.bodies["head"], Assembly(system).bodies["head"]
    rho, water, r, half = 1080.0, 1022.0, 0.01, 0.2 / 4 / 2
    area, second = np.pi * r**2, np.pi * r**4 / 4
    mass, inertia = np.diag([rho, rho + 1.5 * water, rho + 1.5 * water]) * area * half, \
        rho * np.diag([2 * second, second, second]) * half
    clamps = [(np.array([0.02, 0.0, 0.0]), np.eye(3)), (np.array([-0.02, 0.0, 0.0]), np.diag([-1.0, -1.0, 1.0]))]
    rng = np.random.default_rng(3)
    for _ in range(3):
        v, w = rng.normal(size=3), rng.normal(size=3)
        vw = np.concatenate([v, w])
        energy = 0.5 * vw @ head.mass_matrix @ vw
        for p, turn in clamps:
            v_p = v + np.cross(w, p)
            energy += 0.5 * (v_p @ turn @ mass @ turn.T @ v_p + w @ turn @ inertia @ turn.T @ w)
        assert 0.5 * vw @ part.mass_matrix @ vw == pytest.approx(energy, rel=1e-13)
        assert 0.5 * vw @ (part.mass_matrix - part.rigid_mass) @ vw == pytest.approx(0.5 * vw @ head.added_mass @ vw)
    net = (rho - water) * area * half
    assert part.params[NET_MASS] == pytest.approx(head.mass - water * head.volume + 2 * net, rel=1e-13)
    np.testing.assert_allclose(part.params[NET_MOMENT:NET_MOMENT + 3],
                               (head.mass - water * head.volume) * np.array(head.centre_of_mass), rtol=1e-13)
    upwind = Assembly(system, "upwind").bodies["head"]
    np.testing.assert_allclose(upwind.mass_matrix, head.mass_matrix, rtol=0, atol=1e-15)
    assert upwind.params[NET_MASS] == pytest.approx(head.mass - water * head.volume, rel=1e-13)


def test_schur_preconditioner_inverts_the_newton_matrix_of_a_tree():
    # Two arms clamped to a free head (tree joints, no penalty joint): the head is linked to each arm's
    # header and first element both ways, and the Schur complement keeps both blocks, so the
    # preconditioner is I - gamma J to its differences' error (measured 1.9e-8 of each entry's
    # scale); with the links' blocks dropped (the head and each arm on their own, as before the
    # links) it is off by 5.2.
    mat = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    arm = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=mat), 4,
                       cables=[rodmol.Cable((0.005, 0.0), 0.2, tension=0.1)])
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), centre_of_mass=(0.0, 0.004, 0.0), volume=2e-5)
    joints = [rodmol.Joint(("head", (0.02, 0.0, 0.0)), ("a", "base")),
              rodmol.Joint(("head", (-0.02, 0.0, 0.0), np.diag([-1.0, -1.0, 1.0])), ("b", "base"))]
    check = NewtonCheck(Assembly(rodmol.System({"a": arm, "b": arm}, {"head": head}, joints, medium="water",
                                               gravity=(0.0, 0.0, -9.81))), seed=7)
    gamma = 1e-3
    precond = check.preconditioner(gamma)
    assert [link.rod for link in precond.links["head"]] == ["a", "b"]
    v = np.random.default_rng(8).standard_normal(check.assembly.size) * check.scale
    r = check.newton(gamma) @ v
    error = check.error(check.solve(precond, r, gamma), v)
    assert error < 1e-6
    assert check.error(check.apart(precond, r, gamma), v) > 1e5 * error
