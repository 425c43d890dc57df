"""The paper's three tests (section VI, Fig. 7) as tension inputs.

The paper describes the tension histories only in words; our reading
(stated in ``docs/scenarios.md``): every pull ramps linearly from 0 to its
target over ``RAMP`` seconds and every release ramps back to 0 over the
same time.

* Bending: cable 11 to 2 N from t = 0, held until 4 s, then released; 6 s.
* Reaching: cables 3, 11, 1, 9 start at t = 0, 2, 4, 6 s toward 4, 2, 4, 1 N;
  once at target, held 3 s (cables 3, 11) or 1 s (cables 1, 9), then released; 9 s.
* Fetching: cables 2, 5, 11 start at t = 0, 2, 4 s toward 4, 3, 2 N and are
  held to the end; 8 s.
"""

from dataclasses import dataclass

from .arm import paper_arm
from .errors import ParameterError

#: Duration [s] of each tension ramp (our assumption).
RAMP = 0.5


@dataclass(frozen=True)
class Scenario:
    """A named set of cable tension histories and a duration."""

    name: str
    tensions: dict  # cable number -> (t [s], T [N]) knots
    t_end: float  # s
    description: str

    def model(self, n_elements=100, medium="water", **options):
        """The paper's arm driven by this scenario's tensions."""
        return paper_arm(n_elements, medium=medium, tensions=self.tensions, **options)


def _pull(start, target, hold=None):
    """Knots of a pull starting at ``start``, held ``hold`` seconds (None: to the end)."""
    knots = [(start, 0.0), (start + RAMP, target)]
    if hold is not None:
        release = start + RAMP + hold
        knots += [(release, target), (release + RAMP, 0.0)]
    return knots


def bending():
    return Scenario("bending", {11: [(0.0, 0.0), (RAMP, 2.0), (4.0, 2.0), (4.0 + RAMP, 0.0)]}, 6.0,
                    "cable 11 pulled to 2 N, held until 4 s, then released")


def reaching():
    return Scenario("reaching", {3: _pull(0.0, 4.0, 3.0), 11: _pull(2.0, 2.0, 3.0),
                                 1: _pull(4.0, 4.0, 1.0), 9: _pull(6.0, 1.0, 1.0)}, 9.0,
                    "cables 3, 11, 1, 9 pulled in turn, 2 s apart, and released")


def fetching():
    return Scenario("fetching", {2: _pull(0.0, 4.0), 5: _pull(2.0, 3.0), 11: _pull(4.0, 2.0)}, 8.0,
                    "cables 2, 5, 11 pulled in turn, 2 s apart, and held")


SCENARIOS = {"bending": bending, "reaching": reaching, "fetching": fetching}


def get(name):
    """The scenario called ``name`` (``"bending"``, ``"reaching"``, ``"fetching"``)."""
    try:
        return SCENARIOS[name]()
    except (KeyError, TypeError):
        raise ParameterError(f"unknown scenario {name!r}; valid are {sorted(SCENARIOS)}") from None
