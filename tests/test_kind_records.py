"""Adding a load kind, a joint kind or a contact shape is its record
(rodmol.load_kinds.KERNELS) plus its kernel: these tests walk every record
and check that it is wired everywhere it must be, each failure naming the
kind and what it lacks (docs/systems.md, "Adding a joint kind or a contact
shape").

Per record: its compiled branch is dispatched (its code computes something,
and not what another kind of its quantity computes: a kind whose branch was
never written falls through to another's), its dependency table is what
its branch reads, its energy is the potential of its force and moment, a
scenario file reaches it, and, for a hold, a Hold and a Joint take it, and
a rod's base joined by it is eliminated exactly when it holds the turning;
for a contact shape, a body moves it as its geometry's roles say.
"""

from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol import load_kinds, loads
from rodmol.discretise import body_joints, external
from rodmol.discretise.assembly import Assembly
from rodmol.discretise.contact_parts import contact_reaction
from rodmol.discretise.layout import StateLayout
from rodmol.discretise.rigid import BQ, BX, FREE_BODY
from rodmol.discretise.rotations import from_matrix, matrices
from rodmol.scenario.file import parse_scenario
from rodmol.system_joints import JOINT_KINDS

KINDS = list(load_kinds.KERNELS)
REFERENCE = Path(__file__).resolve().parents[1] / "docs" / "scenario-reference.md"
RADIUS = 0.02  # the section's


def _unit(x):
    return tuple(np.asarray(x, dtype=float) / np.linalg.norm(x))


# A generic state of the node: turned, moving and spinning (every field read makes a difference).
QUAT = _unit((0.9, 0.2, -0.3, 0.25))
V, W = (0.03, -0.02, 0.05), (0.4, -0.7, 0.2)
VALUE = (0.3, -1.2, 2.5)


def _shape_class(name):
    """The contact shape class whose kernel is ``name``, or None."""
    found = [cls for cls in loads.CONTACT_SHAPES if cls.kernel == name]
    return found[0] if found else None


def _shape(name):
    """A contact shape of kernel ``name`` with generic geometry (points apart, unit directions)."""
    cls = _shape_class(name)
    assert cls is not None, f"contact kind {name!r}: no class of rodmol.loads.CONTACT_SHAPES has kernel {name!r}"
    roles = load_kinds.KERNELS[name].geometry
    vectors = {f: (np.array(_unit((0.2, 1.0, 0.1))) if role == "direction" else np.array([0.1, -0.05, 0.02]) * (k + 1))
               for k, (f, role) in enumerate(zip(cls.vectors, roles))}
    return cls(**vectors, **{f: 0.05 for f in cls.scalars}, stiffness=1e4, damping=20.0, friction=0.3)


def _generic(name):
    """(parameter row, value, u) of a generic entry of kind ``name``: a contact penetrating its
    shape beyond the smoothing depth, a hold displaced and turned off its held pose."""
    kind = load_kinds.KERNELS[name]
    row = np.zeros(loads.N_PARAMS)
    if kind.quantity in ("force", "moment"):
        return row, VALUE, (0.1, 0.2, 0.3)
    if kind.quantity == "hold":
        row[:3], row[3:7] = (0.1, 0.0, 0.0), _unit((0.8, -0.1, 0.35, 0.2))
        row[[loads.P_STIFFNESS, loads.P_DAMPING, loads.P_TURN_STIFFNESS, loads.P_TURN_DAMPING]] = 1e3, 2.0, 5.0, 0.1
        return row, (0.01, 0.02, -0.01), (0.13, -0.02, 0.015)
    shape = _shape(name)
    row[:] = shape.params(np.array([RADIUS]))[0]
    first = shape.shape_vectors()[0]
    return row, (0.0, 0.0, 0.0), tuple(first + 0.5 * RADIUS * np.array(_unit((1.0, 2.0, 3.0))))


def _evaluate(name, code=None, row=None, u=None, quat=QUAT, v=V, w=W):
    """(force, moment) of kind ``name``'s generic entry through the kernel, as code ``code``."""
    own_row, value, own_u = _generic(name)
    code = load_kinds.KERNELS[name].code if code is None else code
    row = own_row if row is None else row
    out = external.load(code, row, value, tuple(own_u if u is None else u), tuple(quat), tuple(v), tuple(w))
    return np.array(out).ravel()


def test_the_records_are_well_formed():
    codes = [k.code for k in load_kinds.KERNELS.values()]
    assert sorted(codes) == list(range(len(codes))), "the records' codes must be 0, 1, 2, ... once each"
    for name, kind in load_kinds.KERNELS.items():
        assert kind.quantity in load_kinds.QUANTITIES, f"kind {name!r}: quantity {kind.quantity!r}"
        assert set(kind.depends) <= {"u", "Q", "v", "w"}, f"kind {name!r}: depends {kind.depends}"
        assert not kind.holds_turning or kind.quantity == "hold", f"kind {name!r}: holds_turning is a hold's"
        if kind.quantity == "contact":
            assert kind.geometry and kind.geometry[0] == "point" and set(kind.geometry) <= set(load_kinds.ROLES), (
                f"contact kind {name!r}: its geometry must list its row's 3-vectors' roles, a point first")
        else:
            assert kind.geometry == (), f"kind {name!r}: geometry is a contact shape's"


@pytest.mark.parametrize("name", KINDS)
def test_each_kind_is_dispatched_to_its_own_branch(name):
    """Its code computes something, and not what any other kind of its quantity computes
    from the same entry (a missing branch falls through to another kind's)."""
    got = _evaluate(name)
    assert np.any(got != 0.0), f"kind {name!r}: its code computes nothing: give it its branch in external.load"
    quantity = load_kinds.KERNELS[name].quantity
    for other, kind in load_kinds.KERNELS.items():
        if other != name and kind.quantity == quantity:
            same = np.allclose(_evaluate(name, code=kind.code), got, rtol=1e-12, atol=0.0)
            assert not same, (f"kind {name!r} computes what {other!r} does: give it its own branch in "
                              "rodmol/discretise/external.py")


def _perturbed(field, u, quat, v, w, h=1e-4):
    """The node's state with ``field`` moved by a small step."""
    state = {"u": np.array(u), "Q": np.array(quat), "v": np.array(v), "w": np.array(w)}
    state[field] = state[field] + h * np.array([0.3, -0.7, 0.5, 0.4][:len(state[field])])
    state["Q"] = state["Q"] / np.linalg.norm(state["Q"])
    return state


@pytest.mark.parametrize("name", KINDS)
def test_each_kinds_dependency_table_is_what_its_branch_reads(name):
    kind = load_kinds.KERNELS[name]
    row, _, u = _generic(name)
    base = _evaluate(name)
    assert external.DEPENDS[kind.code] == kind.depends
    for field in ("u", "Q", "v", "w"):
        moved = _perturbed(field, u, QUAT, V, W)
        reads = not np.allclose(_evaluate(name, u=moved["u"], quat=moved["Q"], v=moved["v"], w=moved["w"]), base,
                                rtol=1e-13, atol=0.0)
        if reads:
            assert field in kind.depends, f"kind {name!r} reads {field!r}: add it to its record's depends"
        else:
            assert field not in kind.depends, f"kind {name!r} declares {field!r} in depends but does not read it"


def _gradient(f, x, h=1e-7):
    x = np.asarray(x, dtype=float)
    return np.array([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


@pytest.mark.parametrize("name", [n for n, k in load_kinds.KERNELS.items() if k.quantity in ("hold", "contact")])
def test_each_penalty_kinds_energy_is_the_potential_of_its_force_and_moment(name):
    """At rest (no velocity: no damping, no friction) the force is minus the energy's gradient in
    the node's position and the moment minus its derivative in the section's turning (local axes)."""
    kind = load_kinds.KERNELS[name]
    row, value, u = _generic(name)
    still = (0.0, 0.0, 0.0)
    force, moment = _evaluate(name, v=still, w=still).reshape(2, 3)
    r = matrices(np.array(QUAT))
    if kind.quantity == "contact":
        def energy(x, quat=QUAT):
            return external.contact_energy(kind.code, row, tuple(x))
    else:
        def energy(x, quat=QUAT):
            return external.hold_energy(kind.code, row, value, tuple(x), tuple(quat))
    assert energy(u) > 0.0, f"kind {name!r}: no energy: give it its branch in external's energy"
    np.testing.assert_allclose(-_gradient(energy, u), r @ force, rtol=1e-5, atol=1e-9 * np.abs(force).max(),
                               err_msg=f"kind {name!r}: its energy is not its force's potential")
    if kind.quantity == "hold":
        def turned(angles):
            half = 0.5 * np.asarray(angles)
            return energy(u, tuple(_product(QUAT, (1.0, *half))))
        turning = -_gradient(turned, np.zeros(3))
        np.testing.assert_allclose(turning, moment, rtol=1e-5, atol=1e-9 * max(1.0, np.abs(moment).max()),
                                   err_msg=f"kind {name!r}: its energy is not its moment's potential")
        assert (np.abs(moment).max() > 0.0) == kind.holds_turning, (
            f"kind {name!r}: its moment and its record's holds_turning disagree")


def _product(a, b):
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3, a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1, a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)


def _reached(build):
    """The kernels a scenario [[load]] type's constructor can make."""
    cls = loads._builds(build)
    if cls is rodmol.Hold:  # its kernel is its kind
        return set(load_kinds.HOLD_KINDS)
    kernels = getattr(cls, "_kernels", None)
    return set(kernels.values()) if kernels else {cls.kernel}


@pytest.mark.parametrize("name", KINDS)
def test_each_kind_has_its_scenario_key(name):
    reached = {kind for kind, (build, _) in loads.SCENARIO_TYPES.items() if name in _reached(build)}
    assert reached, f"kind {name!r}: no [[load]] type of rodmol.loads.SCENARIO_TYPES makes it"
    if load_kinds.KERNELS[name].quantity == "contact":
        assert set(reached) <= set(loads.CONTACT_TYPES), f"contact kind {name!r}: its types must be CONTACT_TYPES"


HOLD_NAMES = list(load_kinds.HOLD_KINDS)
JOINT_FILE = """\
[solver]
t_end = 0.1
[discretization]
n_elements = 4
[[rod]]
name = "beam"
length = 0.2
radius = 0.005
[rod.material]
E = 1e7
nu = 0.5
mu = 1000.0
rho = 1000.0
[[rod.load]]
type = "hold"
s = 0.1
kind = "{kind}"
[[joint]]
a = ["beam", "base"]
b = "world"
kind = "{kind}"
[[joint]]
a = ["beam", "tip"]
b = "world"
kind = "{kind}"
"""


@pytest.mark.parametrize("name", HOLD_NAMES)
def test_each_hold_kind_is_a_hold_and_a_joint_from_python_and_files(name):
    """A Hold and a Joint take it (from a scenario file too), a rod's base joined by it is
    eliminated exactly when it holds the turning, the body joints' law turns exactly then,
    and the scenario reference names it as a hold's and a joint's kind."""
    kind = load_kinds.KERNELS[name]
    assert name in JOINT_KINDS
    system = parse_scenario(JOINT_FILE.format(kind=name)).model
    holds = system.rods["beam"].loads
    assert [h.kind for h in holds] == [name, name] and all(h.kernel == name for h in holds)
    assert (system.base_bodies == {}) == kind.holds_turning, (
        f"hold kind {name!r}: a base joined by it must be eliminated exactly when it holds the turning")
    if system.base_bodies:
        (joint,) = system.body_joints
        law = body_joints.joint_law(joint, (_segment_part(system), None), 1e3)
        assert law[2] == 0.0 and law[3] == 0.0
    rows = [line for line in REFERENCE.read_text().splitlines() if line.startswith("| `kind` |")]
    assert len(rows) == 2 and all(f'`"{name}"`' in row for row in rows), (
        f"hold kind {name!r}: docs/scenario-reference.md's `kind` rows ([[load]] hold, [[joint]]) must name it")


def _segment_part(system):
    return Assembly(system).bodies["beam.base"]


@pytest.mark.parametrize("name", [n for n, k in load_kinds.KERNELS.items() if k.quantity == "contact"])
def test_each_contact_shape_is_moved_by_a_body_as_its_roles_say(name):
    """A shape in a body's frame, placed by the body's pose (Python, rodmol.Contact) and moved
    by the compiled body part give the same row, and the node's depth against it is the depth of
    the node's point in the body frame against the shape there (its points moved, directions turned)."""
    shape = _shape(name)
    assert len(shape.vectors) == len(load_kinds.KERNELS[name].geometry), (
        f"contact shape {name!r}: its class's vectors and its record's geometry roles must match")
    turn = matrices(np.array(_unit((0.7, 0.3, -0.4, 0.5))))
    position = np.array([0.3, -0.1, 0.2])
    placed = shape.placed(position, turn, "placed")
    expected = placed.params(np.array([RADIUS]))[0]
    body = np.zeros(FREE_BODY.size)
    body[BX:BX + 3], body[BQ:BQ + 4] = position, from_matrix(turn)
    row = shape.params(np.array([RADIUS]))[0].copy()
    moves = np.array([1.0 if role == "point" else 0.0 for role in load_kinds.KERNELS[name].geometry])
    y = StateLayout(1).pack(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]), np.zeros((1, 3)),
                            np.array([[1.0, 0.0, 0.0, 0.0]]), np.zeros((1, 3)), np.zeros((1, 3)),
                            np.zeros((1, 3)), np.zeros((1, 3)))
    node = StateLayout(1).header
    contact_reaction(load_kinds.KERNELS[name].code, row, y, node, body, shape.shape_vectors(), moves, 0.01)
    n = 3 * len(shape.vectors)
    np.testing.assert_allclose(row[:n], expected[:n], atol=1e-12, err_msg=(
        f"contact shape {name!r}: the compiled body part and the shape's placed() move it differently"))
    point = np.array(_generic(name)[2])
    depth_body, _ = external.contact_depth(load_kinds.KERNELS[name].code, shape.params(np.array([RADIUS]))[0],
                                           tuple(point))
    depth_placed, _ = external.contact_depth(load_kinds.KERNELS[name].code, expected, tuple(position + turn @ point))
    assert depth_body > 0.0 and depth_placed == pytest.approx(depth_body, rel=1e-12), (
        f"contact shape {name!r}: placed by a body, it is not where the body's pose puts it: check its "
        "record's geometry roles (a point moves with the body, a direction turns only)")
