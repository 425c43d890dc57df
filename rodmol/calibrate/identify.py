"""Parameter identification: fit dotted parameters of a scenario to measured
marker tracks by bounded least squares, the model runs of each Jacobian
fanned out in parallel.

The residual is the difference between simulated and measured marker
positions at every measured sample, divided by the arm length L (a system's:
its longest rod's; so its mean norm per marker is eq. (15)'s error). Missing samples are left out. The
Jacobian is built from forward differences, one model run per parameter,
all at once on the executor, or (``jacobian="exact"``) from the forward
sensitivities of the run itself (:mod:`rodmol.sensitivities`: one run gives
the residual and its Jacobian); scipy's trust-region reflective method
(``least_squares(method="trf")``) keeps the parameters within their bounds.
"""

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .. import _checks, named_parameters
from ..errors import ParameterError
from .paper_errors import ErrorTable
from .parallel import SERIAL, check_picklable, executor
from .runs import MarkersAndSlopes, MarkersAt, Task, failed_run
from .targets import of_spec
from .variants import apply, as_spec, current, split_key

#: Residual entry [-] (a fraction of L) for a sample after a run stopped early.
FAILED_RESIDUAL = 1.0
#: How the Jacobian is built: forward differences of runs, or the runs' own sensitivities.
JACOBIANS = ("differences", "exact")


@dataclass
class Fit:
    """An identification: for each parameter (in order of ``names``) its
    ``start``, fitted ``value`` and standard uncertainty ``sigma`` (from the
    Jacobian at the optimum and the residual variance), its ``bounds``;
    ``correlation`` between the fitted parameters; ``residual`` the rms
    marker distance [m] at the optimum; ``errors_before`` and
    ``errors_after`` the errors of eq. (15) (ErrorTables) at the start and at
    the optimum; ``runs`` the model runs done."""

    names: list
    start: np.ndarray
    value: np.ndarray
    sigma: np.ndarray
    bounds: np.ndarray
    correlation: np.ndarray
    residual: float
    errors_before: ErrorTable
    errors_after: ErrorTable
    runs: int
    success: bool
    message: str

    @property
    def values(self):
        """{name: fitted value}."""
        return dict(zip(self.names, self.value.tolist()))

    def table(self, truth=None):
        """The result as a Markdown table; ``truth`` ({name: value}) adds the true
        values and the errors of the fit (synthetic data)."""
        head = "| parameter | start | fitted | 1 sigma | sigma [%] |"
        rule = "|---|---:|---:|---:|---:|"
        if truth:
            head, rule = head + " true | error [%] |", rule + "---:|---:|"
        lines = [head, rule]
        for i, name in enumerate(self.names):
            row = (f"| {name} | {self.start[i]:.6g} | {self.value[i]:.6g} | {self.sigma[i]:.3g} | "
                   f"{100 * self.sigma[i] / abs(self.value[i]):.2f} |")
            if truth:
                true = truth[name]
                row += f" {true:.6g} | {100 * (self.value[i] - true) / true:+.2f} |"
            lines.append(row)
        b, a = self.errors_before, self.errors_after
        lines += ["", f"residual (rms marker distance): {1e3 * self.residual:.3f} mm; {self.runs} model runs; "
                  f"{self.message}",
                  f"eq. (15) mean / tip error: start {100 * b.mean_average:.2f}% / {100 * b.tip_average:.2f}%, "
                  f"fitted {100 * a.mean_average:.2f}% / {100 * a.tip_average:.2f}%"]
        return "\n".join(lines)


def identify(spec, measured, parameters, *, start=None, client=None, rel_step=1e-2, max_iterations=30,
             tolerance=1e-6, progress=None, n_workers=None, jacobian="differences"):
    """Fit ``parameters`` of ``spec`` to the measured markers.

    Parameters
    ----------
    spec : RunSpec or scenario path
        The run (its tensions should be the measured ones): a rod's or a system's.
    measured : MarkerTracks, CSV path
        Measured markers [m], global frame, in the order of the model's
        markers. A system's: MarkerTracks whose ``part`` names what they see
        (a rod's markers, ``"<rod>.tip"``, a body), or {part: tracks or CSV
        path} for several parts of one recording (:mod:`rodmol.calibrate.targets`).
    parameters : {dotted key: (lower, upper)}
        The parameters to fit and their bounds (e.g. ``{"material.E": (50e3,
        300e3), "medium.Cy,Cz": (0.5, 5)}``; a system's ``{"rods.arm1.material.E":
        ..., "bodies.head.mass": ...}``; see :mod:`rodmol.calibrate.variants`).
    start : {dotted key: value}, optional
        Starting values; default: the values in ``spec``.
    client : see :mod:`rodmol.calibrate.parallel` (None: a LocalCluster)
    rel_step : float
        Forward-difference step, relative to each parameter's start (large
        enough to stand well above the integrator's tolerance).
    max_iterations, tolerance : the least-squares iterations (Jacobians) and
        the relative change of cost and parameters at which it stops.
    progress : callable ``progress(iteration, cost)``, optional
    jacobian : "differences" or "exact"
        ``"differences"``: one run per parameter at ``rel_step`` (all at once on
        the executor); ``"exact"``: the forward sensitivities of each run
        (``simulate(..., sensitivities=...)``, CVODE or RK23), so one run gives
        the residual and its Jacobian; the parameters must then be
        :mod:`rodmol.named_parameters` (numbers, not the run's settings).

    Returns
    -------
    Fit
    """
    spec = as_spec(spec)
    exact = _checks.choice("jacobian", jacobian, JACOBIANS) == "exact"
    tracks, targets = of_spec(spec, measured)
    names, lower, upper, x0, scale = _parameters(spec, parameters, start or {})
    if exact:
        named_parameters.parameters(spec.model, names)  # each a number the run differentiates by
    if tracks.t[-1] > spec.t_end + 1e-12:
        spec = apply(spec, {"solver.t_end": float(tracks.t[-1])})
    if client != SERIAL:
        check_picklable(spec)
    length = targets.length
    seen = np.isfinite(tracks.xyz)
    task = Task(spec, MarkersAt(tracks.t, targets), keep=False)
    if exact:
        task = Task(spec, MarkersAndSlopes(tracks.t, targets, tuple(names)), keep=False,
                    options=(("sensitivities", tuple(names)),))
    cache, slopes = {}, {}

    def overrides(x):
        return {name: float(v) for name, v in zip(names, x * scale)}

    def simulate(points, ex):
        outcomes = ex.map(task, [overrides(x) for x in points], failed=failed_run)
        for x, o in zip(points, outcomes):
            value = o.value
            if exact:
                value, derivatives = value if value is not None else (None, None)
                slopes[tuple(x)] = _slopes(derivatives, names, seen, length, scale)
            simulated = value if value is not None else np.full(tracks.xyz.shape, np.nan)  # a failed run
            cache[tuple(x)] = _residual(simulated, tracks.xyz, seen, length)
        return [cache[tuple(x)] for x in points]

    with executor(client, n_workers) as ex:
        counter = {"runs": 0, "iterations": 0}

        def fun(x):
            if tuple(x) not in cache:
                counter["runs"] += 1
                simulate([x], ex)
            return cache[tuple(x)]

        def jac(x):
            if exact:
                fun(x)
                counter["iterations"] += 1
                if progress:
                    progress(counter["iterations"], 0.5 * float(cache[tuple(x)] @ cache[tuple(x)]))
                return slopes[tuple(x)]
            f0 = fun(x)
            steps = rel_step * np.maximum(np.abs(x), 1.0)
            steps = np.where(x + steps > upper / scale, -steps, steps)  # stay inside the bounds
            points = [x + np.eye(len(x))[j] * steps[j] for j in range(len(x))]
            counter["runs"] += len(points)
            columns = simulate(points, ex)
            counter["iterations"] += 1
            if progress:
                progress(counter["iterations"], 0.5 * float(f0 @ f0))
            return np.column_stack([(f - f0) / h for f, h in zip(columns, steps)])

        fit = least_squares(fun, x0 / scale, jac=jac, bounds=(lower / scale, upper / scale),
                            method="trf", x_scale="jac", max_nfev=max_iterations, ftol=tolerance,
                            xtol=tolerance, gtol=tolerance)
    value = fit.x * scale
    sigma, correlation = _uncertainty(fit.jac, fit.fun, scale)
    markers = int(np.sum(np.all(seen, axis=-1)))
    residual = length * float(np.sqrt(np.sum(fit.fun**2) / max(markers, 1)))
    before = _errors(cache[tuple(x0 / scale)], tracks, seen, length, "start")
    after = _errors(cache[tuple(fit.x)] if tuple(fit.x) in cache else fun(fit.x), tracks, seen, length,
                    "fitted")
    return Fit(names, x0, value, sigma, np.column_stack([lower, upper]), correlation, residual, before,
               after, counter["runs"], bool(fit.success), fit.message)


def _parameters(spec, parameters, start):
    if not parameters:
        raise ParameterError("give at least one parameter to identify, e.g. {'material.E': (50e3, 300e3)}")
    names, lower, upper, x0 = [], [], [], []
    for name, bounds in parameters.items():
        try:
            lo, hi = (float(b) for b in bounds)
        except (TypeError, ValueError):
            raise ParameterError(f"parameter {name!r}: bounds must be (lower, upper), got {bounds!r}") from None
        value = float(start.get(name, current(spec, name)))
        if not lo < hi or not lo <= value <= hi:
            raise ParameterError(f"parameter {name!r}: need lower < upper and a start within them, got "
                                 f"bounds {bounds!r} and start {value!r}")
        split_key(name)
        apply(spec, {name: value})  # checks the key
        names.append(name)
        lower.append(lo)
        upper.append(hi)
        x0.append(value)
    x0 = np.array(x0)
    # Work in units of each start (or of the bounds' span for a zero start), so
    # that the steps and the trust region treat all parameters alike.
    scale = np.where(x0 != 0.0, np.abs(x0), np.array(upper) - np.array(lower))
    return names, np.array(lower), np.array(upper), x0, scale


def _slopes(derivatives, names, seen, length, scale):
    """The Jacobian of the residual by the scaled parameters from the markers'
    derivatives ({name: d markers / d name}); zero columns for a failed run."""
    if derivatives is None:
        return np.zeros((int(np.sum(seen)), len(names)))
    columns = [np.nan_to_num(derivatives[name][seen] / length * s) for name, s in zip(names, scale)]
    return np.column_stack(columns)


def _residual(simulated, measured, seen, length):
    """(simulated - measured) / L over the seen samples; FAILED_RESIDUAL where
    the run had stopped."""
    diff = (simulated - measured)[seen] / length
    return np.where(np.isfinite(diff), diff, FAILED_RESIDUAL)


def _uncertainty(jac, residual, scale):
    """Standard deviations of the parameters and their correlations, from
    cov = s^2 (J^T J)^-1 with s^2 = |r|^2 / (m - n)."""
    m, n = jac.shape
    variance = float(residual @ residual) / max(m - n, 1)
    cov = variance * np.linalg.pinv(jac.T @ jac)
    sigma = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = cov / np.outer(sigma, sigma)
    return sigma * scale, correlation


def _errors(residual, tracks, seen, length, name):
    """eq. (15) from a residual vector (the simulated markers are measured + residual L)."""
    diff = np.full(tracks.xyz.shape, np.nan)
    diff[seen] = residual * length
    dist = np.linalg.norm(diff, axis=-1) / length
    return ErrorTable(tracks.t, dist[:, -1], np.mean(dist, axis=1), np.ones(len(tracks.t), bool), name)
