"""Dense central differences of a vector function, for the few columns the
control and linearisation tools need (the right-hand side's banded Jacobian
has its own coloured builder, :mod:`rodmol.discretise.jacobian`)."""

import numpy as np


def central_columns(fn, y, entries, steps):
    """d fn / d y[entries] by central differences, shape (len(fn(y)), len(entries)).

    ``steps`` (len(entries),) are the perturbations of each entry, in its units.
    """
    columns = []
    for i, step in zip(entries, steps):
        up, down = y.copy(), y.copy()
        up[i] += step
        down[i] -= step
        columns.append((np.asarray(fn(up)) - np.asarray(fn(down))) / (2 * step))
    return np.stack(columns, axis=1)
