"""Helpers of the calibration tests: small scenarios and synthetic recordings."""

import numpy as np

import rodmol
from rodmol.calibrate import calibrate_dlt, spec_of, synthetic, triangulate
from rodmol.scenario.file import parse_scenario

#: The paper's values of the parameters the tests identify.
TRUTH = {"material.E": 110e3, "material.mu": 300.0, "medium.Cy,Cz": 2.5}


def paper_spec(scenario, n_elements=10, **solver):
    """A RunSpec of one of the paper's tests on a coarse grid."""
    text = f'name = "{scenario}"\narm = "paper"\nscenario = "{scenario}"\n'
    text += f"[discretization]\nn_elements = {n_elements}\n"
    if solver:
        text += "[solver]\n" + "".join(f"{k} = {v!r}\n" for k, v in solver.items())
    return parse_scenario(text)


def pulse_spec(n_elements=10):
    """The synthetic identification experiment (sharp tension pulses on cables 11 and 2)."""
    tensions, t_end = synthetic.pulse_tensions()
    return spec_of(rodmol.paper_arm(n_elements, tensions=tensions), t_end, output_dt=0.01)


def reconstruct(experiment):
    """Markers of a synthetic recording, rebuilt from its control points and pixel tracks."""
    cameras = [calibrate_dlt(experiment.control_xyz, uv) for uv in experiment.control_uv]
    return triangulate(cameras, experiment.pixels)


def rms(a, b):
    return float(np.sqrt(np.nanmean(np.sum((a - b) ** 2, axis=-1))))


class KillOnce:
    """A constant tension [N] that kills the worker process first evaluating it: the
    first call outside the process that built it (the tests') creates ``marker`` and
    sends the process SIGKILL, mid-task; every later call just returns the tension."""

    def __init__(self, marker, tension=0.3):
        import os

        self.marker, self.tension, self.home = str(marker), float(tension), os.getpid()

    def __call__(self, t):
        import os
        import signal

        if os.getpid() != self.home:
            try:
                os.close(os.open(self.marker, os.O_CREAT | os.O_EXCL))
            except FileExistsError:
                pass
            else:
                os.kill(os.getpid(), signal.SIGKILL)
        return self.tension
