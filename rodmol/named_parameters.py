"""Named parameters of a model: which exist, their values, and the model rebuilt at other values.

A parameter is named by the calibration's dotted key (:mod:`rodmol.model_variants`,
:mod:`rodmol.system_variants`) and is a continuous number, or a few of them:

* ``material.E``, ``material.nu``, ``material.G``, ``material.mu``, ``material.rho``;
* ``medium.rho``, ``medium.Cx``, ``medium.Cy``, ``medium.Cz``, ``medium.By``,
  ``medium.Bz``; a comma-joined key, ``medium.Cy,Cz``, is one parameter that
  sets every field it names to one value (their values must agree);
* ``tension.<cable>``: the knot values [N] of a knot input
  (:class:`rodmol.inputs.Knots`, one value per knot: a parameter of several
  components, in knot order) or the value of a constant tension;
  ``tension.<cable>.scale`` [-] and ``tension.<cable>.offset`` [N];
* of a :class:`rodmol.System`: ``rods.<rod>.<key>`` (a rod's key above),
  ``medium.<number>`` (the system's medium), ``bodies.<body>.mass``,
  ``bodies.<body>.volume`` and one component of a body's vector,
  ``bodies.<body>.inertia.<i>``, ``.centre_of_mass.<i>``, ``.added_mass.<i>``,
  ``.drag.<i>``; a rod's key without ``rods.<rod>.`` (every rod's).

Not parameters: the structure (``discretization.n_elements``, the scheme, the
switches of ``[medium]``), the run's keys, and inputs that are not numbers
(a function of time, a feedback law, a scaled input's knots). Changing a
parameter rebuilds the model through the variants (no recompilation: the
compiled right-hand side reads its physics from arrays); :meth:`Parameter.pair`
is the one rule for the two models a central difference reads.
"""

from dataclasses import dataclass

import numpy as np

from . import _checks, system_variants
from . import model_variants as rod_variants
from .cables import Tension
from .errors import ParameterError
from .inputs import Constant, Knots
from .systems import System

#: Relative step of the central differences: h = REL_STEP * scale.
REL_STEP = 1e-6
#: Units of the fields that are parameters, by field name [SI].
UNITS = {"E": "Pa", "G": "Pa", "nu": "-", "mu": "Pa s", "rho": "kg/m^3", "Cx": "-", "Cy": "-", "Cz": "-",
         "By": "-", "Bz": "-", "tension": "N", "scale": "-", "offset": "N", "mass": "kg", "volume": "m^3",
         "inertia": "kg m^2", "centre_of_mass": "m", "added_mass": "kg or kg m^2", "drag": "-"}
#: The interval each field's value must lie in (the model refuses others); a
#: difference's two values stay inside it (:meth:`Parameter.pair`).
BOUNDS = {"nu": (-1.0, 0.5), "mu": (0.0, np.inf), "tension": (0.0, np.inf), "Cx": (0.0, np.inf),
          "Cy": (0.0, np.inf), "Cz": (0.0, np.inf), "By": (0.0, np.inf), "Bz": (0.0, np.inf),
          "rho": (0.0, np.inf), "volume": (0.0, np.inf), "drag": (0.0, np.inf), "added_mass": (0.0, np.inf)}
#: Structural and run keys: refused with the reason.
NOT_PARAMETERS = {"discretization.n_elements": "the grid is structure, not a parameter",
                  "discretization.scheme": "the scheme is structure, not a parameter"}


@dataclass(frozen=True)
class Parameter:
    """One named parameter of a model (see the module docstring).

    Attributes
    ----------
    key : str
        The key as given (``"material.E"``, ``"tension.11"``, ``"medium.Cy,Cz"``).
    fields : tuple of str
        The single-field keys it sets (several for a comma-joined key).
    value : (m,) array
        Its current value [``unit``]: one number, or a knot input's m knot values.
    unit : str
        Its SI unit.
    knots : (m,) array or None
        The knot times [s] of a tension's knots; None for a number.
    scale : float
        Its typical magnitude [``unit``]: the largest |value|, or 1 if all are 0.
    """

    key: str
    fields: tuple
    value: np.ndarray
    unit: str
    knots: np.ndarray | None
    scale: float

    @property
    def size(self):
        """Number of components (knots of a tension, else 1)."""
        return len(self.value)

    @property
    def step(self):
        """The central differences' step h [``unit``]: ``REL_STEP * scale``."""
        return REL_STEP * self.scale

    def at(self, model, value):
        """``model`` rebuilt with this parameter at ``value`` ((m,) or a number for m = 1)."""
        value = np.broadcast_to(np.asarray(value, dtype=float), self.value.shape)
        if self.knots is not None:
            new = Tension(Knots(self.knots, value, source=f"{self.key} varied"))
        elif _tension_value(self.fields[0]):
            new = Tension(Constant([float(value[0])], 1))
        else:
            new = float(value[0])
        changes = dict.fromkeys(self.fields, new)
        if isinstance(model, System):
            return system_variants.variant(model, changes)
        return rod_variants.variant(model, changes)

    def pair(self, model, component=0, step=None):
        """The two models of a central difference in component ``component``:
        (model at p + h + c, model at p - h + c, h), h = ``step`` or :attr:`step`.
        The shift c is 0 unless p - h or p + h leaves the field's interval
        (:data:`BOUNDS`, e.g. a zero tension or drag coefficient): then c = h
        or -h, and the difference is the derivative at p + c, off by O(h)."""
        h = self.step if step is None else float(step)
        low, high = BOUNDS.get(_field_name(self.fields[0]), (-np.inf, np.inf))
        p = float(self.value[component])
        shift = h if p - h < low else (-h if p + h > high else 0.0)
        up, down = self.value.copy(), self.value.copy()
        up[component] += h + shift
        down[component] += -h + shift
        return self.at(model, up), self.at(model, down), h


def parameters(model, keys):
    """The :class:`Parameter` of each key of ``keys`` (a key or a list of keys) of
    ``model`` (a Model or a System), checked before any work: an unknown key, a
    structural or run key, an input that is not numbers, or a key given twice is a
    ParameterError naming it."""
    if isinstance(keys, str):
        keys = [keys]
    try:
        keys = list(keys)
    except TypeError:
        raise ParameterError(f"parameter keys must be a list of dotted names such as 'material.E', "
                             f"got {_checks.short(keys)}") from None
    out = [parameter(model, key) for key in keys]
    seen = {}
    for p in out:
        for field in p.fields:
            if field in seen:
                raise ParameterError(f"parameter {p.key!r}: {field!r} is given twice (also by {seen[field]!r})")
            seen[field] = p.key
    return tuple(out)


def parameter(model, key):
    """The :class:`Parameter` named ``key`` of ``model`` (see :func:`parameters`)."""
    fields = rod_variants.split_key(key)
    for field in fields:
        _refuse_structure(key, field)
    values = [_value(model, key, field) for field in fields]
    first = values[0]
    for field, value in zip(fields[1:], values[1:]):
        if np.shape(value) != np.shape(first) or not np.array_equal(value, first):
            raise ParameterError(f"parameter {key!r}: its fields differ ({fields[0]} = {_shown(first)}, "
                                 f"{field} = {_shown(value)}); one parameter sets them to one value")
    knots, value = first if isinstance(first, tuple) else (None, np.atleast_1d(np.asarray(first, dtype=float)))
    scale = float(np.max(np.abs(value))) or 1.0
    unit = "N" if knots is not None or _tension_value(fields[0]) else UNITS.get(_field_name(fields[0]), "")
    return Parameter(key, tuple(fields), value, unit, knots, scale)


def _refuse_structure(key, field):
    """A ParameterError saying why ``field`` (of ``key``) is not a parameter, if it is not."""
    for name, why in NOT_PARAMETERS.items():
        if field == name or field.endswith("." + name):
            raise ParameterError(f"{key!r} is not a parameter: {why}")
    if field.startswith("solver."):
        raise ParameterError(f"{key!r} is not a parameter: it is a setting of the run")
    tail = field.split(".")
    if len(tail) >= 2 and tail[-2] == "medium" and tail[-1] in rod_variants.SWITCHES:
        raise ParameterError(f"{key!r} is not a parameter: a switch (true/false) has no derivative")


def _value(model, key, field):
    """The value of one field: a float, or (knot times, knot values) of a tension's knots."""
    try:
        if isinstance(model, System):
            value = system_variants.value(model, field)
        else:
            value = rod_variants.value(model, field)
    except ParameterError as exc:
        raise ParameterError(f"parameter {key!r}: {exc}") from None
    if isinstance(value, Tension):
        signal = value.signal if not value.feedback else None
        if isinstance(signal, Knots) and signal.width == 1:
            return signal.times.copy(), signal.values[:, 0].copy()
        if isinstance(signal, Constant):
            return float(signal.value(0.0))
        raise ParameterError(f"parameter {key!r}: the tension is {_checks.short(value)}; only knots "
                             "(t, T) and a constant tension have values to differentiate by")
    arr = np.asarray(value, dtype=float) if not isinstance(value, bool) else None
    if arr is None or arr.ndim != 0:
        raise ParameterError(f"parameter {key!r} is not a number (it is {_checks.short(value)}): name one "
                             f"component, e.g. '{field}.0'")
    return float(arr)


def _field_name(field):
    """The last name of a field's key (``rods.arm.material.E`` -> ``E``), a tension's ``tension``."""
    parts = field.split(".")
    if "tension" in parts:
        return parts[-1] if parts[-1] in ("scale", "offset") else "tension"
    if parts[-1].isdigit():
        return parts[-2]
    return parts[-1]


def _tension_value(field):
    """True if ``field`` names a tension input itself (not its scale or offset)."""
    return _field_name(field) == "tension"


def _shown(value):
    return _checks.short(value[1] if isinstance(value, tuple) else value)
