"""Property: random Python values for the parameters of Material, Rod, Cable,
Marker, Model and simulate either give a valid object (or an accepted call) or
raise rodmol's ParameterError, never a raw Python error or a huge allocation."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rodmol
from rodmol.errors import ParameterError

SETTINGS = settings(max_examples=150, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**30, max_value=10**30),
    st.sampled_from([0, 1, 2, -1, 1e-300, 1e300, 0.5, 0.012, 0.3, 110e3, 1080.0, 10**400]),
)
anything = st.one_of(
    numbers, st.none(), st.booleans(), st.text(max_size=6), st.binary(max_size=4),
    st.complex_numbers(max_magnitude=10), st.just(object()), st.just(np.array([1.0, np.nan])),
    st.lists(numbers, max_size=4), st.tuples(numbers, numbers),
    st.lists(st.tuples(numbers, numbers), max_size=3), st.dictionaries(st.text(max_size=2), numbers, max_size=2),
    st.just(lambda t: 1.0), st.just(lambda t, state: 1.0), st.just(lambda: 1.0),
)
plausible = {  # mostly sensible values, so the checks past the first are reached too
    "E": st.one_of(st.just(110e3), anything), "nu": st.one_of(st.just(0.5), anything),
    "mu": st.one_of(st.just(300.0), anything), "rho": st.one_of(st.just(1080.0), anything),
    "length": st.one_of(st.just(0.3), anything), "radius": st.one_of(st.just((0.012, 0.005)), anything),
    "offset": st.one_of(st.just((0.004, 0.0)), anything), "anchor": st.one_of(st.just(0.3), anything),
    "tension": st.one_of(st.just(1.0), anything), "s": st.one_of(st.just(0.1), anything),
}
MATERIAL = rodmol.Material(E=110e3, nu=0.5, mu=300.0, rho=1080.0)
ROD = rodmol.Rod(0.3, (0.012, 0.005), MATERIAL)


def accepted_or_refused(build):
    try:
        return build()
    except ParameterError:
        return None


@SETTINGS
@given(E=plausible["E"], nu=plausible["nu"], mu=plausible["mu"], rho=plausible["rho"])
def test_material(E, nu, mu, rho):
    material = accepted_or_refused(lambda: rodmol.Material(E=E, nu=nu, mu=mu, rho=rho))
    if material is not None:
        assert all(np.isfinite([material.E, material.G, material.mu, material.rho]))
        assert material.E > 0 and material.G > 0 and material.rho > 0 and material.mu >= 0


@SETTINGS
@given(length=plausible["length"], radius=plausible["radius"])
def test_rod(length, radius):
    rod = accepted_or_refused(lambda: rodmol.Rod(length, radius, MATERIAL))
    if rod is not None:
        r = rod.radius_at(np.linspace(0.0, rod.length, 5))
        assert np.all(np.isfinite(r) & (r > 0))


@SETTINGS
@given(offset=plausible["offset"], anchor=plausible["anchor"], tension=plausible["tension"],
       name=st.one_of(st.just("c"), anything), s=plausible["s"], marker_offset=anything)
def test_cable_marker_and_model(offset, anchor, tension, name, s, marker_offset):
    def build():
        cable = rodmol.Cable(offset, anchor, tension, name=name)
        marker = rodmol.Marker(s, offset=marker_offset)
        return rodmol.Model(ROD, 6, cables=[cable], markers=[marker])
    model = accepted_or_refused(build)
    if model is not None:
        assert 0 < model.cables[0].anchor <= ROD.length
        assert np.hypot(*model.marker_offsets[0, 1:]) <= ROD.radius_at(min(model.markers[0].s, 0.3))


@SETTINGS
@given(n=st.one_of(st.integers(min_value=-5, max_value=10**12), anything), gravity=anything,
       medium=st.one_of(st.sampled_from(["water", "air", "oil"]), anything))
def test_model(n, gravity, medium):
    model = accepted_or_refused(lambda: rodmol.Model(ROD, n, gravity=gravity, medium=medium))
    if model is not None:
        assert 2 <= model.n_elements <= rodmol.model.MAX_ELEMENTS


OPTION_NAMES = st.sampled_from(["linsolver", "max_step", "max_order", "jacobian", "max_nonlin_iters",
                                "linsolvr", "tol", "rtol_", "maxstep"])


@settings(SETTINGS, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(t_end=numbers, rtol=st.one_of(st.just(1e-6), anything), output_dt=st.one_of(st.just(0.01), anything),
       backend=st.one_of(st.sampled_from(["cvode", "rk23", "CVODE"]), anything),
       initial=st.one_of(st.sampled_from(["equilibrium", "straight", "equilibirum"]), anything),
       progress=st.one_of(st.none(), anything), max_wall_time=st.one_of(st.none(), anything),
       options=st.dictionaries(OPTION_NAMES, anything, max_size=2))
def test_simulate_arguments(checks_only, t_end, rtol, output_dt, backend, initial, progress, max_wall_time,
                            options):
    model = rodmol.Model(ROD, 6)
    with pytest.raises((ParameterError, checks_only)):
        rodmol.simulate(model, t_end, rtol=rtol, output_dt=output_dt, backend=backend, initial=initial,
                        progress=progress, max_wall_time=max_wall_time, **options)
