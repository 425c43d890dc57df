"""Shared cases of the gradient tests (test_gradients, test_losses, control/test_optimal_tensions):
the models, the loss's times and targets, the tolerances and the agreement asserted."""

import numpy as np

import rodmol

#: The adjoint's run; the reference: central differences of runs at REFERENCE_RTOL, step REFERENCE_STEP * scale.
RTOL, REFERENCE_RTOL, REFERENCE_STEP = 1e-8, 1e-10, 1e-3
#: The agreement asserted, relative to the largest component of the gradient (measured 1e-7 .. 4e-6).
AGREEMENT = 1e-4
KNOTS = [(0.0, 0.0), (0.2, 2.0), (0.5, 1.0)]
TIMES = np.array([0.1, 0.25, 0.4, 0.5])
TARGETS = np.array([[0.0, 0.3, 0.05], [0.0, 0.28, 0.08], [0.01, 0.27, 0.1], [0.0, 0.26, 0.1]])


def _arm(knots=KNOTS):
    return rodmol.paper_arm(8, tensions={11: knots})


def _system():
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    cable = rodmol.Cable((0.005, 0.0), 0.2, name="c", tension=[(0.0, 0.0), (0.1, 0.2), (0.3, 0.1)])
    arm = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), 6, cables=[cable])
    head = rodmol.RigidBody(0.05, (2e-5, 3e-5, 4e-5), centre_of_mass=(0.0, 0.004, 0.0))
    return rodmol.System({"arm": arm}, {"head": head}, [rodmol.Joint(("head", (0.02, 0.0, 0.01)), ("arm", "base"))],
                         gravity=(0.0, -9.81, 0.0), medium="water")


def agree(gradient, expected, largest):
    error = float(np.max(np.abs(np.asarray(gradient) - expected)) / abs(largest))
    print(f"relative error {error:.2e}")
    assert largest != 0 and error < AGREEMENT
