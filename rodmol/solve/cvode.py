"""SUNDIALS CVODE (BDF) through scikit-sundae, of a rod or a system of rods and bodies."""

from .outputs import Outputs, run_steps
from .stepping import Stepper
from .watch import Watch


def cvode(system, y0, t_out, *, rtol, atol, progress=None, max_wall_time=None, linsolver="auto",
          max_step=0.0, jacobian="auto", max_order="auto", max_nonlin_iters=3):
    """SUNDIALS CVODE (BDF) through scikit-sundae, of ``system`` (any
    :class:`rodmol.discretise.protocol.Discretised`).

    ``linsolver`` is how the Newton systems (I - gamma J) x = r are solved,
    one of those the system offers (``system.linear_solvers()``):

    * ``"gmres"``: GMRES preconditioned by the system's own preconditioner
      (``system.preconditioner``: of a rod an exact O(N) solve of the
      structured Newton matrix, so it converges in one or two iterations);
    * ``"band"``: SUNDIALS' band LU of the full system (the half-bandwidths
      come from ``system.bandwidths()``);
    * ``"lapackband"``, ``"sparse"`` (SuperLU_MT on ``system.pattern()``),
      ``"dense"`` (small systems only);
    * ``"auto"``: the system's first (a rod's: "gmres" from
      ``rodmol.discretise.system.GMRES_MIN_ELEMENTS`` elements on or when it has a global coupling,
      feedback tensions, if the preconditioner can solve its structure,
      else "band"; a system of rods and bodies: "gmres"; see
      ``docs/performance.md``).

    ``jacobian`` chooses how the direct solvers get J:

    * ``"sundials"``: SUNDIALS' own finite differences for the band and dense
      solvers, scikit-sundae's coloured differences for ``"sparse"``;
    * ``"compiled"``: ``system.jacobian`` (a rod's: finite differences inside
      numba with the colouring derived from the system's dependencies),
      handed over as ``jacfn``;
    * ``"auto"``: what the system offers with that solver (a rod's:
      "compiled" for "sparse" and "gmres", "sundials" otherwise, measured
      fastest with the band solvers, whose ``jacfn`` template is a dense
      (n, n) array; a system's: "sundials" for "sparse").

    ``max_order`` caps the BDF order (1-5); ``"auto"`` is 5, or 2 when every
    mode of the grid oscillates (``system.lightly_damped``): BDF 3-5 are not
    stable near the imaginary axis, and there they either take many short
    steps or let the energy grow, while BDF2 is A-stable (see
    ``docs/model.md``). ``max_nonlin_iters`` caps the Newton iterations
    per step (SUNDIALS' default 3: order 4 and 5 Newton iterations save ~10%
    on the paper's tests but double the steps of an inviscid oscillation).

    Every internal step is checked by :class:`rodmol.solve.watch.Watch`
    (blow-ups, degenerate elements, stalls, the wall-time budget
    ``max_wall_time`` [s]), which also reports ``progress`` between outputs.
    The steps are :class:`rodmol.solve.stepping.Stepper`'s, the stepping
    simulator's too; the outputs are interpolated inside them.
    """
    stepper = Stepper(system, t_out[0], y0, rtol=rtol, atol=atol, linsolver=linsolver, max_step=max_step,
                      jacobian=jacobian, max_order=max_order, max_nonlin_iters=max_nonlin_iters)
    watch = Watch(system, t_out, max_wall_time, progress)
    out = Outputs(t_out, y0, progress, system, "CVODE", watch)

    def stats():
        info = stepper.stats()
        del info["restarts"]  # a run starts CVODE once
        return info

    def stop(reason, error=None):
        return out.stopped(reason, error, **stats())

    t_end = float(t_out[-1])
    # As Python floats: the loop below compares them at every step, where numpy's scalars cost.
    times, frames = out.t_out.tolist(), len(out.t_out)

    def steps():
        while out.next_index < frames:
            # Towards the next output: CVODE sizes its first step by the distance to it (towards
            # t_end, a contact's damped bounce kept ringing at 1 % where it settles at rtol); at
            # the inputs' knots at the latest: a rod at rest takes long steps and would stride
            # over a short ramp that starts between two of them.
            r, problem = stepper.step(times[out.next_index], stepper.stop_time(t_end), watch)
            if problem:  # the frames inside a broken step are not kept either
                return stop(problem)
            t, k = r.t, out.next_index
            if k < frames and times[k] <= t:
                stepper.mark()  # an output frame reached: the right-hand sides are watched afresh
                while k < frames and times[k] <= t:
                    out.add(r.y if times[k] == t else stepper.interpolate(times[k]))
                    k += 1
            slow = watch.pace(t, r.y)
            if slow and k < frames:
                return stop(slow)

    def now():
        return stepper.failed_at if stepper.failed_at is not None else stepper.reached

    return run_steps(steps, stop, out, stats, now=now)
