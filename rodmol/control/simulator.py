"""The stepping simulator: a model advanced one control period at a time.

It sits on the control floor: it drives the integrator (:mod:`rodmol.solve`),
builds a :class:`rodmol.Result` and streams into :mod:`rodmol.output`, as
:func:`rodmol.simulate` does, for a controller that runs outside it.
"""

import time
from dataclasses import dataclass

import numpy as np

from .. import _checks
from ..discretise.schemes import DEFAULT_SCHEME
from ..errors import IntegrationError, ParameterError
from ..model import Model
from ..run_arguments import check_run, fit, prepare_run
from ..run_kinds import run_kind
from ..simulate import _sink
from ..solve.stepping import Stepper
from .held import HeldInputs
from .held_system import SystemHeld


@dataclass(frozen=True, eq=False)
class Snapshot:
    """A saved state of a :class:`Simulator` (:meth:`Simulator.copy`), for :meth:`Simulator.reset`.

    ``t`` [s], ``state`` (the state vector, ``rodmol.StateLayout``), ``held`` (the
    held inputs' values) and the frames recorded up to it.
    """

    t: float
    state: np.ndarray
    held: tuple
    frames: tuple  # (times, states, held rows) recorded up to here
    owner: object


class Simulator:
    """A model (one rod, or a System of rods and bodies) advanced by :meth:`step`, with its
    inputs held over each step.

    The system, the compiled kernels, the checks and the integrator (CVODE)
    are built once; every :meth:`step` integrates over ``dt`` with the held
    inputs constant (a zero-order hold), and CVODE is re-initialised only
    where a held input changes (or after :meth:`copy` and :meth:`reset`).

    Held inputs: every cable's tension [N] (or, for a displacement-controlled
    cable, its actuator position z [m]) and every point load's vector
    (:class:`rodmol.PointForce` [N], :class:`rodmol.PointMoment` [N m], in the
    load's frame). They start at the model's inputs at ``t0`` and keep the
    last value commanded: a tension schedule in the model is read at ``t0``
    only. Distributed loads, contact and a moving base act as in
    :func:`rodmol.simulate` (functions of time, not held). Feedback tensions
    ``T(t, state)`` are refused: the controller is the caller.

    A :class:`rodmol.System`: each rod's inputs are held as a single rod's, and
    each driven body's velocity and angular velocity (body frame, as its
    :class:`rodmol.BaseMotion` gives them at ``t0``); :meth:`step` takes them
    by part (``tensions={"arm1": {"cable 2": 1.5}}``, ``motions={"platform":
    {"velocity": (3,)}}``), :attr:`state` is a view per part
    (``sim.state["arm1"].tip``, ``sim.state["head"].position``) and
    :attr:`result` a :class:`rodmol.SystemResult`.

    Parameters
    ----------
    model : Model or System
    initial, scheme, rtol, atol, t0 :
        As for :func:`rodmol.simulate` (``initial="equilibrium"`` is the rest
        state under the inputs held at ``t0``; None is simulate's default: a
        rod's equilibrium, a System's "straight", at rest).
    progress : bool or callable, optional
        True announces the preparation (compiled kernels, initial
        equilibrium) on standard error; a callable ``progress(t, t_step_end)``
        is called during long steps, every half second of wall time.
    max_wall_time : float, optional
        Wall-time budget [s] of each step.
    out : path or sink, optional
        Stream the frames (one at the end of each step) into this directory
        (``result.h5`` and ParaView's ``rod.xdmf``, see ``docs/paraview.md``;
        a System's ``system.h5`` and a folder per rod) as :func:`rodmol.simulate` does; call :meth:`close` (or use the
        simulator in a ``with`` block) to finish the files. A streamed
        simulator cannot be :meth:`reset` to an earlier time.
    overwrite : bool
        With ``out``: replace an earlier run in that directory (as for
        :func:`rodmol.simulate`, which otherwise refuses it).
    backend : "cvode"
        The only backend (an integrator kept alive between steps).
    **backend_options
        CVODE's options (``linsolver``, ``jacobian``, ``max_order``,
        ``max_step``, ``max_nonlin_iters``), checked as by simulate.
    """

    def __init__(self, model, initial=None, *, scheme=DEFAULT_SCHEME, rtol=None, atol=None,
                 t0=None, progress=None, max_wall_time=None, out=None, overwrite=False, backend="cvode",
                 **backend_options):
        if backend != "cvode":
            raise ParameterError(f"`backend` {_checks.short(backend)}: the Simulator keeps CVODE alive "
                                 "between steps and has no other backend")
        kind = run_kind(model)
        args = check_run(initial=initial, t0=t0, scheme=scheme, backend=backend, rtol=rtol, atol=atol,
                         progress=progress, max_wall_time=max_wall_time, backend_options=backend_options,
                         kind=kind)
        self._inputs = (HeldInputs if isinstance(model, Model) else SystemHeld).of(model)
        self._row = self._inputs.initial_row(args.t0)
        live, self._held = self._inputs.live(self._row)
        self.max_wall_time, self._scheme, self._kind = args.max_wall_time, args.scheme, kind
        self._system = kind.discretise(live, args.scheme)
        args = fit(args, self._system)
        self._sink = _sink(args.kind, out, False, overwrite)  # after every check: `overwrite` clears the earlier run
        announce = args.progress
        if announce is True:
            from .._progress import Progress

            announce = Progress()
        try:
            y0, self._timings = prepare_run(self._system, args, announce, self._sink)
        finally:
            if args.progress is True:
                announce.close()
        self._report = None if args.progress is True else args.progress
        self._stepper = Stepper(self._system, args.t0, y0, rtol=args.rtol, atol=args.atol,
                                **args.backend_options)
        self._times, self._states, self._rows = [args.t0], [self._stepper.y], [self._row]
        self._restart, self._closed, self._stored, self._wall = False, False, 0, 0.0
        self._token = object()  # snapshots belong to this simulator
        if self._sink is not None:
            # The writer derives each chunk's arrays from the record so far (only ever appended to).
            record = self._inputs.recorded(self._times, self._rows)
            self._sink.begin(kind.discretise(record, self._scheme), None)  # no planned end

    # ----------------------------------------------------------------- stepping

    @property
    def t(self):
        """Current time [s]."""
        return self._stepper.t

    @property
    def y(self):
        """A copy of the current state vector (layout: ``rodmol.StateLayout``)."""
        return self._stepper.y.copy()

    @property
    def state(self):
        """The current state as a :class:`rodmol.StateView` (tip, positions, markers,
        cable lengths, strains, velocities); a System's by part
        (:class:`rodmol.discretise.system_state_view.SystemStateView`)."""
        return self._system.state_view(self.t, self._stepper.y)

    @property
    def held(self):
        """The held inputs by name: ``{"tensions": {cable: N}, "displacements": {cable: m},
        "loads": {load: (3,)}}``; a System's by part, ``{rod: that, driven body:
        {"velocity": (3,), "angular_velocity": (3,)}}``."""
        return self._inputs.by_name(self._row)

    def held_model(self):
        """The model with the inputs held now as constants (a tension schedule of the model
        replaced by its held value): with :attr:`y` and :attr:`t`, the operating point a
        model-based controller linearises about, ``rodmol.linearize(sim.held_model(), sim.y, sim.t)``."""
        return self._inputs.constant(self._row)

    def step(self, dt, tensions=None, *, displacements=None, loads=None, motions=None):
        """Advance by ``dt`` [s] with the inputs held; returns the new :attr:`state`.

        ``tensions`` [N]: a dict {cable name or index: tension}, or one number
        per cable; ``displacements`` [m]: a dict {cable: actuator position} for
        displacement-controlled cables; ``loads``: a dict {point load name or
        index: (3,) vector} [N or N m]. Inputs not given keep their value.
        A System's by rod, each as a rod's: ``tensions={"arm1": {"cable 2": 1.5}}``;
        ``motions`` sets its driven bodies' velocities, ``{body: {"velocity": (3,)
        [m/s], "angular_velocity": (3,) [rad/s]}}``, body frame.

        Raises
        ------
        ParameterError
            Bad arguments (named), before any work.
        IntegrationError
            The step failed (solver failure, blow-up, wall-time budget): the
            message says where and why, ``__cause__`` is the exception that
            ended it if any; the simulator stays at its state before the step.
        """
        if self._closed:
            raise ParameterError("this Simulator's output is closed: make a new one to go on")
        dt = _checks.positive("dt", dt, " s")
        row = self._inputs.command(self._row, tensions, displacements, loads, motions)
        t_start = self.t
        t_end = t_start + dt
        if not t_end > t_start:
            raise ParameterError(f"`dt` = {dt!r} s is below the time resolution at t = {t_start!r} s")
        changed = not _same(row, self._row)
        if changed:
            self._hold(row)
        started = time.perf_counter()
        # Inputs that jumped restart CVODE here, and are likely to jump again at the step's
        # end: its steps end there. Held ones let its steps run on past it, as simulate's.
        failed = self._stepper.advance(t_end, restart=changed or self._restart, exact_end=changed,
                                       max_wall_time=self.max_wall_time, progress=self._report)
        self._wall += time.perf_counter() - started
        if failed:
            if changed:
                self._hold(self._row)
            reason, error = failed
            raise IntegrationError(f"the step from t = {t_start:.6g} s to {t_end:.6g} s failed "
                                   f"(the simulator stays at t = {t_start:.6g} s): {reason}") from error
        self._restart, self._row = False, row
        self._times.append(t_end)
        self._states.append(self._stepper.y)
        self._rows.append(row)
        self._stream()
        return self.state

    def _hold(self, row):
        for held, value in zip(self._held, row):
            held.current = value
        self._system.read_held(self.t)

    # ----------------------------------------------------------------- rollouts

    def copy(self):
        """A :class:`Snapshot` of the current state, held inputs and record, for :meth:`reset`.

        The integrator restarts at this point, so the continuation from here and
        from any later ``reset(snapshot)`` are identical to the last bit.
        """
        self._restart = True
        return Snapshot(self.t, self._stepper.y.copy(), self._row,
                        (tuple(self._times), tuple(self._states), tuple(self._rows)), self._token)

    def reset(self, saved):
        """Go back (or forward) to the :class:`Snapshot` ``saved`` of this simulator; returns :attr:`state`."""
        if not isinstance(saved, Snapshot) or saved.owner is not self._token:
            raise ParameterError(f"`saved` must be a Snapshot taken by this Simulator's copy(), "
                                 f"got {_checks.short(saved)}")
        if self._sink is not None:
            raise ParameterError("a Simulator streaming its frames (`out`) cannot be reset: the files "
                                 "record one history; stream a new Simulator instead")
        times, states, rows = saved.frames
        self._times[:], self._states[:], self._rows[:] = times, states, rows
        self._row = saved.held
        self._hold(self._row)
        self._stepper.restart(saved.t, saved.state)
        self._restart = False
        return self.state

    # ----------------------------------------------------------------- the record

    @property
    def stats(self):
        """Steps, evaluations, restarts of the integrator and wall time [s] of the steps."""
        return dict(self._stepper.stats(), **self._timings, backend="cvode", wall_time_s=self._wall)

    @property
    def result(self):
        """A :class:`rodmol.Result` (a System's: a :class:`rodmol.SystemResult`) of the frames
        stepped (the initial one and one per step), as :func:`rodmol.simulate` returns; a frame's tensions, actuator positions and loads
        are the inputs held over the step that ended there. Streaming, the Result reads
        the files (the frames not yet written are stored first)."""
        if self._sink is not None:
            self._stream(force=True)
            self._sink.flush()
            return self._sink.result()
        times, rows = list(self._times), list(self._rows)
        system = self._kind.discretise(self._inputs.recorded(times, rows), self._scheme)
        return self._kind.result(system, np.array(times), np.array(self._states), True,
                                 f"stepped to t = {self.t:.6g} s", self.stats)

    def _stream(self, force=False):
        """Hand the frames not yet stored to the sink, a chunk at a time (all if ``force``)."""
        if self._sink is None:
            return
        waiting = len(self._times) - self._stored
        if waiting and (force or waiting >= self._sink.chunk_frames):
            k = self._stored
            self._sink.frames(np.array(self._times[k:]), np.array(self._states[k:]))
            self._stored = len(self._times)

    def close(self):
        """Finish the streamed output (all frames and the final index written) and return its
        Result; without ``out``, nothing to do (None)."""
        if self._sink is None:
            return None
        if self._closed:
            return self._sink.result()
        self._stream(force=True)
        self._closed = True
        return self._sink.end(True, f"stepped to t = {self.t:.6g} s", self.stats)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self._sink is not None:
            self.close()

    def __repr__(self):
        return f"Simulator(t={self.t:.6g} s, {len(self._times)} frames, {self._inputs.model!r})"


def _same(a, b):
    """True if the held rows ``a`` and ``b`` are equal (numbers, and vectors of point loads)."""
    return all(x == y if isinstance(x, float) else np.array_equal(x, y) for x, y in zip(a, b))
