"""Runs per minute of a sweep: serial in this process versus a dask LocalCluster.

The paper's bending test (6 s, our reading of its tensions) is swept over
values of E at several grid sizes N, first serially, then on LocalClusters of
1 and 2 single-threaded worker processes (``rodmol.sweep(..., client=...)``; the
smoke run starts the first only).
The cluster's start and the workers' first run (loading numba's cached
machine code) are timed apart from the sweep. Each run also rebuilds its
pose for the summary row, in the worker or here. On the cluster, the sweep
is timed twice: returning the summary rows only (``keep=False``, as when the
results go to files) and returning every Result (``keep=True``: each ships
its raw states to this process). The machine's 1-minute load average is
recorded before and after each size: on a shared machine, a worker gets a
core only if nobody else holds it.

    python solvers/sweep_throughput.py [--quick | --smoke] [--out DIR]
"""

import logging
import os

import _common as C
from _common import np, rodmol

from rodmol.calibrate import apply, spec_of, sweep

SCRIPT = "sweep_throughput.py"


def bending(n, t_end):
    scenario = rodmol.scenarios.get("bending")
    return spec_of(scenario.model(n), min(t_end, scenario.t_end))


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    header = C.header_lines(args, SCRIPT)
    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.ERROR)  # no INFO lines as clusters close

    sizes = C.pick(args, [20, 50, 100], [20, 50], [10])
    n_runs = C.pick(args, 16, 8, 2)
    t_end = C.pick(args, 6.0, 6.0, 0.5)
    # The smoke run starts one cluster (each start and first run costs seconds of its own).
    workers = [w for w in C.pick(args, (1, 2), (1, 2), (1,)) if w <= C.os.cpu_count()]
    rows, startup = [], []
    clusters = {}
    for w in workers:
        with C.Stopwatch() as clock:
            cluster = LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None,
                                   silence_logs=50)
            client = Client(cluster)
        with C.Stopwatch() as first:
            sweep(bending(sizes[0], 0.05), [{}] * w, client=client)  # each worker loads the kernels
        clusters[w] = (cluster, client)
        startup.append(dict(workers=w, cluster_start_s=clock.seconds, first_runs_s=first.seconds))
    try:
        for n in sizes:
            spec = bending(n, t_end)
            overrides = [{"material.E": float(e)} for e in np.linspace(80e3, 140e3, n_runs)]
            apply(spec, overrides[0]).simulate()  # warm up this process
            load = os.getloadavg()[0]  # 1-minute load: other users of the cores
            with C.Stopwatch() as clock:
                serial = sweep(spec, overrides, client="serial")
            row = dict(N=n, runs=n_runs, load_before=load, t_end_s=spec.t_end, serial_s=clock.seconds,
                       serial_runs_per_min=60 * n_runs / clock.seconds)
            for w, (_, client) in clusters.items():
                with C.Stopwatch() as clock:
                    summaries = sweep(spec, overrides, client=client, keep=False)
                with C.Stopwatch() as back:
                    parallel = sweep(spec, overrides, client=client, keep=True)
                same = all(np.array_equal(a.result.markers, b.result.markers) and a.value == c.value
                           for a, b, c in zip(serial.runs, parallel.runs, summaries.runs))
                row.update({f"cluster{w}_runs_per_min": 60 * n_runs / clock.seconds,
                            f"cluster{w}_speedup": row["serial_s"] / clock.seconds,
                            f"cluster{w}_with_results_runs_per_min": 60 * n_runs / back.seconds,
                            f"cluster{w}_same": same})
            row["load_after"] = os.getloadavg()[0]
            rows.append(row)
            print(", ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items()),
                  flush=True)
    finally:
        for cluster, client in clusters.values():
            client.close()
            cluster.close()
    base = os.path.join(args.out, "sweep_throughput")
    C.write_csv(base + ".csv", rows, header)
    C.write_csv(base + "_startup.csv", startup, header)
    C.write_markdown(base + ".md", "Sweep throughput: serial versus dask LocalCluster", header, [
        ("Runs per minute (bending test, E swept; wall time of the whole sweep; "
         "`_same`: the cluster's numbers equal the serial ones)", C.markdown_table(rows)),
        ("Cluster start and the workers' first run (once per cluster)", C.markdown_table(startup))])
    print(f"wrote {base}.{{csv,md}} and {base}_startup.csv")


if __name__ == "__main__":
    main()
