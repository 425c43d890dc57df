"""Property: any Python value thrown at any argument of the public
constructors (Model, Rod, Material, Medium, Cable, Marker, BaseMotion, the
loads and RodContact) gives a valid object or a rodmol error saying what is wrong, never a
raw Python error (TypeError, AttributeError, LinAlgError, ...)."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rodmol
from rodmol.errors import RodmolError

SETTINGS = settings(max_examples=150, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**30, max_value=10**30),
    st.sampled_from([0, 1, 2, -1, 1e-300, 1e300, 0.5, 0.004, 0.3, 10**400]),
)
MATERIAL = rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
ROD = rodmol.Rod(0.3, (0.012, 0.005), MATERIAL)
CABLE = rodmol.Cable((0.004, 0.0), 0.2)
anything = st.one_of(
    numbers, st.none(), st.booleans(), st.text(max_size=6), st.binary(max_size=4),
    st.complex_numbers(max_magnitude=10), st.just(object()), st.just(np.array([1.0, np.nan])),
    st.just(np.zeros((3, 3))), st.just(np.eye(3)), st.just({1, 2}), st.just(iter([1.0, 2.0])),
    st.lists(numbers, max_size=4), st.tuples(numbers, numbers), st.tuples(numbers, numbers, numbers),
    st.lists(st.tuples(numbers, numbers), max_size=3), st.dictionaries(st.text(max_size=2), numbers, max_size=2),
    st.just(lambda *a: 1.0), st.just(lambda *a: None), st.just(lambda *a: (1.0, 2.0, 3.0)),
    st.just(lambda: 1.0), st.sampled_from(["water", "global", "local", "morison", "componentwise"]),
    st.sampled_from([ROD, MATERIAL, CABLE, rodmol.Marker(0.1), rodmol.PointForce(0.3, (0.0, 1.0, 0.0)),
                     rodmol.BaseMotion(), rodmol.Medium(1000.0)]),
    st.lists(st.sampled_from([CABLE, rodmol.Marker(0.1), 1.0, None]), max_size=2),
)

#: Each constructor with sensible arguments; the test replaces one or two of them.
SENSIBLE = {
    rodmol.Model: dict(rod=ROD, n_elements=6, gravity=(0.0, -9.81, 0.0), medium=None, medium_density=0.0,
                       cables=(CABLE,), base=None, drag=True, added_mass=True, viscosity=True,
                       munk_moment=False, markers=(rodmol.Marker(0.1),), loads=(), drag_law="morison",
                       drag_coefficients=None),
    rodmol.Rod: dict(length=0.3, radius=(0.012, 0.005), material=MATERIAL, rest_curvature=(0.0, 0.0, 5.0),
                     rest_stretch=(1.0, 0.0, 0.0)),
    rodmol.Material: dict(E=110e3, nu=0.5, mu=300.0, rho=1080.0),
    rodmol.Medium: dict(rho=1000.0, Cx=0.01, Cy=2.5, Cz=2.5, By=1.5, Bz=1.5),
    rodmol.Cable: dict(offset=(0.004, 0.0), anchor=0.3, tension=1.0, name="c", outside_body=False,
                       friction=0.0, slip_speed=1e-4),
    "actuated cable": dict(offset=(0.004, 0.0), anchor=0.3, name="c", displacement=-0.001, compliance=1e-3,
                           base_to_actuator=0.0, rest_length=None),
    rodmol.Marker: dict(s=0.1, offset=None, name="m"),
    rodmol.BaseMotion: dict(velocity=None, angular_velocity=None, position=(0.0, 0.0, 0.0), rotation=np.eye(3)),
    rodmol.PointForce: dict(s=0.3, force=(0.0, 1.0, 0.0), frame="global", name="f"),
    rodmol.PointMoment: dict(s=0.3, moment=(0.0, 0.0, 1.0), frame="local", name="m"),
    rodmol.DistributedForce: dict(force=(0.0, 1.0, 0.0), frame="global", name="f"),
    rodmol.DistributedMoment: dict(moment=(0.0, 0.0, 1.0), frame="global", name="m"),
    rodmol.PlaneContact: dict(point=(0.0, -0.1, 0.0), normal=(0.0, 1.0, 0.0), stiffness=1e3, damping=0.0,
                              friction=0.2, slip_speed=1e-4, smoothing_depth=None, name="floor"),
    rodmol.CapsuleContact: dict(start=(0.1, -0.1, 0.0), end=(0.2, -0.1, 0.0), radius=0.02, stiffness=1e3,
                                damping=0.0, friction=0.2, slip_speed=1e-4, smoothing_depth=None, name="bar"),
    rodmol.SphereContact: dict(centre=(0.1, -0.1, 0.0), radius=0.02, stiffness=1e3, damping=0.0,
                               friction=0.2, slip_speed=1e-4, smoothing_depth=None, name="ball"),
    rodmol.RodContact: dict(a="left", b="right", stiffness=None, damping=None, friction=0.2, slip_speed=1e-4,
                            smoothing_depth=None),
}


@st.composite
def calls(draw):
    """(constructor, keyword arguments) with one or two arguments replaced by anything."""
    which = draw(st.sampled_from(list(SENSIBLE)))
    kwargs = dict(SENSIBLE[which])
    for name in draw(st.lists(st.sampled_from(sorted(kwargs)), min_size=1, max_size=2, unique=True)):
        kwargs[name] = draw(anything)
    return (rodmol.Cable if which == "actuated cable" else which), kwargs


def test_sensible_arguments_build():
    for which, kwargs in SENSIBLE.items():
        (rodmol.Cable if which == "actuated cable" else which)(**kwargs)


@SETTINGS
@given(call=calls())
def test_constructors_build_or_refuse(call):
    build, kwargs = call
    try:
        build(**kwargs)
    except RodmolError as error:
        assert str(error), "a rodmol error says what is wrong"


@settings(SETTINGS, max_examples=60)
@given(call=calls())
def test_objects_built_from_any_arguments_make_a_model(call):
    """What a constructor accepted also goes into a Model (or is refused there)."""
    build, kwargs = call
    try:
        part = build(**kwargs)
    except RodmolError:
        return
    slot = {rodmol.Cable: "cables", rodmol.Marker: "markers", rodmol.BaseMotion: "base",
            rodmol.Rod: "rod", rodmol.Medium: "medium", rodmol.Material: None}.get(build, "loads")
    if slot is None or isinstance(part, rodmol.Model):
        return
    arguments = dict(SENSIBLE[rodmol.Model], cables=(), markers=())
    arguments[slot] = part if slot in ("base", "rod", "medium") else [part]
    try:
        rodmol.Model(**arguments)
    except RodmolError as error:
        assert str(error)
