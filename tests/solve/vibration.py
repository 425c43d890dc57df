"""Free-vibration measurements shared by the dynamics tests."""

import numpy as np


def measure_free_vibration(t, x):
    """Natural frequency and damping ratio of a decaying oscillation x(t).

    Zero crossings (linear interpolation; exact at a sine's inflection to
    second order) give the damped period T_d; a least-squares line through
    log|x| at the extremes (parabolic interpolation of the samples) gives the
    decay rate sigma: successive extremes of a damped sine are T_d / 2 apart and
    their ratio is exp(-sigma T_d / 2), which is the log decrement.
    Returns (omega_n, zeta).
    """
    i = np.flatnonzero(np.sign(x[1:]) != np.sign(x[:-1]))
    crossings = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    period = 2.0 * np.mean(np.diff(crossings))

    j = np.flatnonzero((np.abs(x[1:-1]) >= np.abs(x[:-2])) & (np.abs(x[1:-1]) > np.abs(x[2:]))) + 1
    a, b, c = np.abs(x[j - 1]), np.abs(x[j]), np.abs(x[j + 1])
    shift = 0.5 * (a - c) / (a - 2.0 * b + c)  # vertex of the parabola, in samples
    peak_t = t[j] + shift * (t[1] - t[0])
    peak_x = b - 0.25 * (a - c) * shift
    sigma = -np.polyfit(peak_t, np.log(peak_x), 1)[0]

    omega_d = 2.0 * np.pi / period
    omega_n = np.hypot(omega_d, sigma)
    return omega_n, sigma / omega_n
