"""A linear model for control about an operating point:
dx/dt = A x + B u + f0, output = y0 + C x + D u, or its sampled form
x[k+1] = A x[k] + B u[k] + f0 under a zero-order hold.

x is the state's deviation from the operating point, u the inputs' from
their values there (``u0``); the drift f0 is the rates at the operating
point, zero at an equilibrium, so a model taken about a state in motion
predicts its motion too. :func:`~rodmol.calibrate.linearize.linearize`
makes one over the whole state; :meth:`output` picks an output (the tip
position), :meth:`reduced` keeps the modes that carry most of the
input-to-output response, and :meth:`discretize` samples it for a control
period.
"""

import numpy as np
import scipy.linalg

from .. import _checks
from ..errors import ParameterError

#: Named outputs of a model over the whole state.
OUTPUTS = ("tip",)
#: A mode whose input or output coupling is below this fraction of the
#: largest is neither driven nor seen: the rod's redundant coordinates
#: (positions and orientations integrate the velocities, a zero eigenvalue
#: per coordinate) and the quaternion norm's restoring modes, which the
#: inputs do not move (their couplings are rounding, 1e-9 of the others).
DECOUPLED = 1e-6


class LinearModel:
    """A linear time-invariant model; ``A, B = model`` unpacks its state matrices.

    dx/dt = A x + B u + f0 and output = y0 + C x + D u (sampled: x[k+1] =
    A x[k] + B u[k] + f0), with x the model's state (:meth:`coordinates` of a
    state vector) and u = inputs - u0.

    Attributes
    ----------
    A, B : arrays (n, n), (n, m)
    C, D : arrays (p, n), (p, m), or None (the output is the whole state)
    inputs, outputs : tuples of str
        The inputs' names with units (see ``linearize``); the outputs' names,
        empty when the output is the whole state.
    u0 : (m,) array
        The inputs' values at the operating point [their units], in the order
        of ``inputs`` (the held tensions, actuator positions, load components).
    y0 : (p,) array or None
        The outputs at the operating point (the tip there [m]); None when the
        output is the whole state (see ``state``).
    f0 : (n,) array
        The drift: the rates dx/dt at the operating point (the system's
        rates there, zero at an equilibrium); of a sampled model, the
        state's change over one period from the operating point with u = 0.
    bounds : (m, 2) array
        Lower and upper bound of each input's value (not of u): tensions
        [0, inf) (cables only pull), the others unbounded.
    dt : float or None
        Sample period [s] of a discretised model; None for continuous time.
    state, t : the operating point (state vector) and time [s]; ``x`` is the
        deviation ``y - state`` (y a state vector)
    projection : (n, size) array or None
        Of a reduced model: its state is ``projection @ (y - state)`` for a
        full state y near the operating point.
    """

    def __init__(self, A, B, C=None, D=None, *, inputs, outputs=(), state=None, t=0.0, dt=None,
                 projection=None, named_outputs=None, u0=None, y0=None, f0=None, bounds=None):
        self.A, self.B, self.C, self.D = A, B, C, D
        self.inputs, self.outputs = tuple(inputs), tuple(outputs)
        self.state, self.t, self.dt, self.projection = state, t, dt, projection
        n, m = np.shape(B)
        self.u0 = np.zeros(m) if u0 is None else np.asarray(u0, dtype=float)
        if y0 is None:
            y0 = None if C is None else np.zeros(len(C))
        self.y0 = None if y0 is None else np.asarray(y0, dtype=float)
        self.f0 = np.zeros(n) if f0 is None else np.asarray(f0, dtype=float)
        self.bounds = (np.tile([-np.inf, np.inf], (m, 1)) if bounds is None
                       else np.asarray(bounds, dtype=float))
        self._named = dict(named_outputs or {})  # name -> (C rows over the whole state, names, values)
        self._modes = None  # (eigenvalues, right, left eigenvectors) of A
        self._owner = self  # the model whose A this one shares (and its modes)

    def __iter__(self):
        return iter((self.A, self.B))

    def __repr__(self):
        kind = "continuous" if self.dt is None else f"sampled every {self.dt} s"
        return (f"LinearModel({self.A.shape[0]} states, {self.B.shape[1]} inputs, "
                f"{len(self.outputs) or 'full-state'} outputs, {kind})")

    def _replace(self, **changes):
        fields = dict(A=self.A, B=self.B, C=self.C, D=self.D, inputs=self.inputs, outputs=self.outputs,
                      state=self.state, t=self.t, dt=self.dt, projection=self.projection,
                      named_outputs=self._named, u0=self.u0, y0=self.y0, f0=self.f0, bounds=self.bounds)
        fields.update(changes)
        model = LinearModel(**fields)
        if "A" not in changes:
            model._owner = self._owner
        return model

    def modes(self):
        """Eigenvalues [1/s] and right and left eigenvectors of A (columns,
        rows), computed once (a dense eigendecomposition: the cost of
        :meth:`reduced`) and shared with the models this one makes."""
        owner = self._owner
        if owner._modes is None:
            lam, right = scipy.linalg.eig(owner.A)
            owner._modes = lam, right, np.linalg.inv(right)
        return owner._modes

    def coordinates(self, y):
        """The model's state x for the state vector ``y`` (``rodmol.StateLayout``): its
        deviation from the operating point, projected onto the kept modes of a reduced model."""
        x = np.asarray(y, dtype=float) - self.state
        return x if self.projection is None else self.projection @ x

    def output(self, output="tip"):
        """The same model with output ``output``: ``"tip"``, the tip position
        [m] (global frame, rebuilt from the orientations and strains as
        ``Result.tip``), a system's ``"<rod>/tip"`` or ``"<body>/position"``,
        or a (p, n) matrix C, the output C times the model's state vector
        (``y0 = C @ state``; of a reduced model C x, ``y0 = 0``)."""
        if isinstance(output, str):
            names = tuple(self._named) or OUTPUTS  # a system's: "<rod>/tip", "<body>/position"
            if output not in names:
                raise ParameterError(f"`output` must be one of {names} or a matrix, got {output!r}"
                                     + _checks.did_you_mean(output, names))
            if output not in self._named or self.projection is not None:
                raise ParameterError(f"`output` {output!r} needs a model over the whole state (from linearize)")
            c, names, values = self._named[output]
            return self._replace(C=c, D=np.zeros((len(c), self.B.shape[1])), outputs=names, y0=values)
        c = _checks.floats(output)
        if c is None or c.ndim != 2 or c.shape[1] != self.A.shape[0] or not np.all(np.isfinite(c)):
            raise ParameterError(f"`output` must be 'tip' or a finite (p, {self.A.shape[0]}) matrix, "
                                 f"got {_checks.short(output)}")
        y0 = c @ self.state if self.projection is None else np.zeros(len(c))
        return self._replace(C=c, D=np.zeros((len(c), self.B.shape[1])),
                             outputs=tuple(f"output {i}" for i in range(len(c))), y0=y0)

    def reduced(self, output=None, order=None):
        """A reduced model of (at least) ``order`` states: modal truncation with static correction.

        The modes of A that the inputs do not drive or the output does not
        see are dropped (see ``DECOUPLED``); the others are ranked by their
        share of the static gain, |C v_i| |w_i B| / |lambda_i| (v_i, w_i the
        right and left eigenvectors), and the first ``order`` are kept, a
        complex pair whole, in real block form. The dropped modes' static
        response goes into D, so the reduced model's static gain is the full
        model's: the fast dynamics are treated as instantaneous. The drift
        f0 is projected alike (the reduced f0 is the kept modes' part), but the
        dropped modes' response to it is left out: about a state in motion the
        drift drives slow modes too (some have |lambda| ~ 1e-3 1/s there), which
        a static correction would treat as settled, so a reduced model predicts
        the motion about such a state less well than the full one.

        Parameters
        ----------
        output : str or (p, n) array, optional
            As for :meth:`output`; default this model's (which must have one).
        order : int, optional
            States to keep (one more if the last kept mode is one of a pair);
            default every mode the inputs drive and the output sees.
        """
        if self.dt is not None:
            raise ParameterError("`reduced` needs a continuous-time model (reduce, then discretize)")
        model = self if output is None else self.output(output)
        if model.C is None:
            raise ParameterError("`reduced` needs an output: give `output` (e.g. 'tip')")
        if order is not None:
            order = _checks.integer_at_least("order", order, 1)
        lam, right, left = model.modes()
        gain_in = np.linalg.norm(left @ model.B, axis=1)
        gain_out = np.linalg.norm(model.C @ right, axis=0)
        coupled = (gain_in > DECOUPLED * gain_in.max()) & (gain_out > DECOUPLED * gain_out.max())
        tiny = np.finfo(float).eps * np.max(np.abs(lam))
        share = np.where(coupled, gain_in * gain_out / np.maximum(np.abs(lam), tiny), -1.0)
        ranked = [i for i in np.argsort(-share, kind="stable") if coupled[i]]
        order = len(ranked) if order is None else order
        if order > len(ranked):
            raise ParameterError(f"`order` must be at most {len(ranked)} (the modes the inputs drive and the "
                                 f"output sees), got {order}")
        kept, columns, rows = set(), [], []
        for i in ranked:
            if len(columns) >= order:
                break
            if i in kept:
                continue
            kept.add(i)
            if lam[i].imag == 0.0:
                columns.append(right[:, i].real)
                rows.append(left[i].real)
                continue
            twin = _conjugate(lam, i)
            kept.add(twin)
            # x = 2 Re(v xi) = Re(v) (2 Re xi) + Im(v) (-2 Im xi), xi = w x.
            columns += [right[:, i].real, right[:, i].imag]
            rows += [2.0 * left[i].real, -2.0 * left[i].imag]
        basis, projection = np.column_stack(columns), np.vstack(rows)
        dropped = [i for i in ranked if i not in kept]
        static = sum((np.outer(model.C @ right[:, i], left[i] @ model.B) / lam[i] for i in dropped),
                     np.zeros(model.D.shape, dtype=complex))
        return model._replace(A=projection @ model.A @ basis, B=projection @ model.B, C=model.C @ basis,
                              D=model.D - static.real, projection=projection, f0=projection @ model.f0)

    def discretize(self, dt):
        """The model sampled every ``dt`` [s] with the inputs held over each
        period (zero-order hold): A_d = exp(A dt), B_d = int_0^dt exp(A s) ds B
        and the drift's f0_d = int_0^dt exp(A s) ds f0, all from one matrix
        exponential of [[A, B, f0], [0, 0, 0]] dt. C, D and y0 stay."""
        if self.dt is not None:
            raise ParameterError(f"the model is already sampled (every {self.dt} s)")
        dt = _checks.positive("dt", dt, " s")
        n, m = self.B.shape
        augmented = np.zeros((n + m + 1, n + m + 1))
        augmented[:n, :n], augmented[:n, n:n + m], augmented[:n, -1] = self.A, self.B, self.f0
        exp = scipy.linalg.expm(augmented * dt)
        # contiguous copies: products with the strided blocks of exp were 100 times slower
        part = np.ascontiguousarray
        return self._replace(A=part(exp[:n, :n]), B=part(exp[:n, n:n + m]), f0=part(exp[:n, -1]), dt=dt)

    def static_gain(self):
        """The output's steady response to constant inputs, (p, m), of a stable
        continuous model whose undriven modes are dropped (a reduced model)."""
        if self.dt is not None or self.C is None or self.projection is None:
            raise ParameterError("`static_gain` is for a reduced continuous-time model (see `reduced`)")
        return self.D - self.C @ np.linalg.solve(self.A, self.B)


def _conjugate(lam, i):
    """Index of the eigenvalue conjugate to lam[i] (the nearest other one)."""
    distance = np.abs(lam - np.conj(lam[i]))
    distance[i] = np.inf
    return int(np.argmin(distance))
