"""A system of rods and rigid bodies (:class:`rodmol.discretise.assembly.Assembly`)
seen through the narrow interface of the single rod's backends, so that
scipy's RK23 (:func:`rodmol.solve.rk23.rk23`) and generalized-alpha
(:func:`rodmol.solve.galpha.generalized_alpha`) integrate it unchanged.

What differs from a rod: each rod's state is checked on its own part by
its own :class:`rodmol.solve.watch.Watch` (:class:`SystemWatch`), the
bodies' entries for finiteness; generalized-alpha's Newton matrix is the
sparse LU on the assembly's Jacobian pattern
(:class:`rodmol.discretise.system_jacobian.SystemJacobian`): the rods' block
elimination leaves the coupling out, so it is refused here
(:meth:`SteppedSystem.preconditioner`); and ``dt="auto"`` is the
shortest of the rods' (:func:`rodmol.solve.galpha.auto_dt` of its ``rods``).
"""

import functools

import numpy as np

from ..discretise.system_jacobian import SystemJacobian
from .watch import Watch


def on_assembly(run):
    """The single rod's backend ``run`` (its options and results) on an assembly, seen through
    :class:`SteppedSystem`."""

    @functools.wraps(run)
    def stepped(assembly, y0, t_out, **options):
        return run(SteppedSystem(assembly), y0, t_out, **options)

    return stepped


class SteppedSystem:
    """``assembly`` for the fixed-step and explicit backends: ``size``,
    ``__call__``, ``layout`` (the assembly: it projects the quaternions of
    every rod and body), ``rods``, ``jacobian``, ``preconditioner`` and ``watch``."""

    def __init__(self, assembly):
        self.assembly = self.layout = assembly
        self.size, self.rods = assembly.size, assembly.rods
        self.lightly_damped = assembly.lightly_damped

    def __call__(self, t, y, out=None):
        return self.assembly(t, y, out)

    def jacobian(self, scale, matrix="sparse"):
        """The system's Jacobian by coloured differences on its pattern (sparse only)."""
        if matrix != "sparse":
            raise ValueError(f"a system's Jacobian is sparse only, not {matrix!r}")
        return SystemJacobian(self.assembly, scale)

    def preconditioner(self, scale):
        """Refused (ValueError): the rods' exact block elimination does not
        take the bodies' coupling, so :func:`rodmol.solve.newton_matrix.newton_matrix`
        falls back to the sparse LU."""
        raise ValueError("the block elimination covers one rod, not a system")

    def watch(self, t_span, max_wall_time=None, progress=None):
        return SystemWatch(self.assembly, t_span, max_wall_time, progress)


class SystemWatch(Watch):
    """A :class:`Watch` over a system: every rod's state checks on its part
    (the message names the rod), the bodies' entries for finiteness; the
    stall test, budget and progress once, the stall's diagnosis on the
    first rod."""

    def __init__(self, assembly, t_span, max_wall_time=None, progress=None):
        self._rods = [(name, assembly.parts[name], Watch(sd, t_span)) for name, sd in assembly.rods.items()]
        self._bodies = [(name, part.slice) for name, part in assembly.bodies.items()]
        first = self._rods[0]
        super().__init__(assembly.rods[first[0]], t_span, max_wall_time, progress)
        self._first = first

    def state(self, t, h, y):
        """Check the state ``y`` of the whole system at the end ``t`` [s] of a step of ``h`` [s]."""
        self.steps += 1
        self.t, self.h_last = t, h
        for name, part, watch in self._rods:
            broken = watch.state(t, h, y[part])
            if broken:
                return f"rod {name!r}: {broken}"
        for name, part in self._bodies:
            if not np.all(np.isfinite(y[part])):
                return f"the state of body {name!r} became non-finite at t = {t:.6g} s: the solution blew up"
        self._worst = self._first[2]._worst
        return None

    def pace(self, t, y):
        return super().pace(t, y[self._first[1]])
