"""Helpers of the output tests: a streamed run killed between two chunks; a small system."""

import numpy as np
import pytest

import rodmol
from rodmol.output.stream import RunWriter
from rodmol.output.system_stream import SystemRunWriter
from rodmol.system_result import SystemResult


class Killed(BaseException):
    """Stands for a SIGKILL between two chunks, once the chunks before are on disk."""


class DiesAfter(RunWriter):
    def __init__(self, directory, chunks, **options):
        super().__init__(directory, **options)
        self.left = chunks

    def frames(self, t, y):
        if self.left == 0:
            self.flush()
            raise Killed
        self.left -= 1
        super().frames(t, y)


class SystemDiesAfter(SystemRunWriter):
    """Killed once ``chunks`` chunks are listed in system.h5; with ``rods_ahead`` the rods have
    stored the next chunk already (killed between their files and system.h5)."""

    def __init__(self, directory, chunks, rods_ahead=False, **options):
        super().__init__(directory, **options)
        self.left, self.rods_ahead = chunks, rods_ahead

    def frames(self, t, y):
        if self.left == 0:
            if self.rods_ahead:
                chunk = SystemResult(self.assembly, t, y, True, "", {})
                for name, writer in self.rods.items():
                    writer.store(chunk[name])
            self.flush()
            raise Killed
        self.left -= 1
        super().frames(t, y)


@pytest.fixture
def killed():
    """``killed(run, directory, chunks, **writer_options)``: call ``run(out=sink)`` with a sink
    (a RunWriter into ``directory``) killed once ``chunks`` chunks are on disk."""

    def kill(run, directory, chunks, **options):
        with pytest.raises(Killed):
            run(out=DiesAfter(directory, chunks, **options))

    return kill


def _two_arms():
    """Two cable-driven arms clamped to a free head in water (one named unfit for a file)."""
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Rod(0.2, radius=(0.012, 0.006), material=material)

    def arm(side):
        pull = rodmol.Cable((side * 0.005, 0.0), 0.2, tension=lambda t: 0.3 * min(t / 0.1, 1.0))
        return rodmol.Model(rod, 6, cables=[pull])

    head = rodmol.RigidBody(mass=0.3, inertia=(2e-4, 3e-4, 4e-4), volume=2.5e-4, centre_of_mass=(0.0, 0.0, 0.01))
    turn = np.diag([-1.0, -1.0, 1.0])
    return rodmol.System(
        rods={"right": arm(1.0), "left arm": arm(-1.0)}, bodies={"head": head},
        joints=[rodmol.Joint(("head", (0.04, 0.0, 0.0)), ("right", "base")),
                rodmol.Joint(("head", (-0.04, 0.0, 0.0), turn), ("left arm", "base"))],
        medium="water", gravity=(0.0, 0.0, -9.81))


@pytest.fixture(scope="session")
def two_arms():
    """``two_arms()``: a new System of two arms on a free head (see :func:`_two_arms`)."""
    return _two_arms


@pytest.fixture
def killed_system():
    """``killed_system(run, directory, chunks, rods_ahead=False, **writer_options)``: call
    ``run(out=sink)`` with a system's sink into ``directory`` killed once ``chunks`` chunks
    are listed in its system.h5 (see :class:`SystemDiesAfter`)."""

    def kill(run, directory, chunks, rods_ahead=False, **options):
        with pytest.raises(Killed):
            run(out=SystemDiesAfter(directory, chunks, rods_ahead, **options))

    return kill
