"""The reduced linear model of the paper's arm for model-predictive control.

The paper's arm pulled by cable 11 at 1 N, in water, linearised at its
equilibrium (``rodmol.linearize``); the tip's response to a unit step of
cable 11 over 5 s, sampled every 10 ms (zero-order hold), of the reduced
models (``LinearModel.reduced(output="tip", order=k)``, modal truncation
with static correction) against the full linear model's: the largest
difference over the response's largest excursion. Also the wall times of
the linearisation, of the eigendecomposition a reduction costs (once per
model) and of one reduction after it.

    python solvers/linear_mpc.py [--quick | --smoke] [--out DIR]
"""

import time

import _common as C
from _common import np, rodmol

SCRIPT = "linear_mpc.py"
ORDERS = (4, 8, 16, 32)
DT, STEPS = 0.01, 500


def step_response(sampled, steps):
    x, u, out = np.zeros(sampled.A.shape[0]), np.eye(sampled.B.shape[1])[10], []
    for _ in range(steps):
        x = sampled.A @ x + sampled.B @ u
        out.append(sampled.C @ x + sampled.D @ u)
    return np.array(out)


def measure(n, steps):
    model = rodmol.paper_arm(n, tensions={11: 1.0})
    y = rodmol.equilibrium(model)
    start = time.perf_counter()
    lin = rodmol.linearize(model, y)
    linearize_s = time.perf_counter() - start
    start = time.perf_counter()
    lin.modes()
    modes_s = time.perf_counter() - start
    full = step_response(lin.output("tip").discretize(DT), steps)
    row = dict(N=n, states=lin.A.shape[0], linearize_s=linearize_s, eigendecomposition_s=modes_s)
    for order in ORDERS:
        start = time.perf_counter()
        reduced = lin.reduced(output="tip", order=order)
        row["reduce_s"] = time.perf_counter() - start
        response = step_response(reduced.discretize(DT), steps)
        row[f"error_{order}_pct"] = float(100 * np.max(np.abs(response - full)) / np.max(np.abs(full)))
    return row


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    sizes = C.pick(args, [10, 30, 100], [10, 30], [6])
    steps = C.pick(args, STEPS, STEPS, 50)
    rows = []
    for n in sizes:
        rows.append(measure(n, steps))
        print(rows[-1])
    header = C.header_lines(args, SCRIPT)
    formats = {f"error_{k}_pct": ".3g" for k in ORDERS}
    formats.update(linearize_s=".3f", eigendecomposition_s=".2f", reduce_s=".3f")
    note = (f"error_k_pct: the reduced model of k states (k + 1 where a complex pair would be split) against "
            f"the full linear model, {steps} steps of {DT} s. reduce_s: one reduction once the eigendecomposition "
            "is done (it is shared by every reduction of the same model).")
    C.write_results(args, "linear_mpc", "Reduced linear models of the paper's arm", header, rows,
                    [("Results", C.markdown_table(rows, formats=formats)), ("Reading", note)])


if __name__ == "__main__":
    main()
