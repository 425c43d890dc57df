"""Versions of the package side by side: one long-lived worker process per tree, answering
JSON commands, for the before/after studies (driver_speed.py, crawl_speed.py).

A study script runs as the parent (with this checkout) and, given ``--worker``, as a
worker: :func:`serve` answers one JSON command per line of standard input with one
line of its own, prefixed with :data:`MARK`; :class:`Version` starts a worker on a
tree (PYTHONPATH, one BLAS thread) and asks it. Must not import _common (which puts
this checkout first on sys.path): the workers import it too.
"""

import json
import os
import subprocess
import sys

MARK = "@@worker@@ "


def serve(make, handlers):
    """The worker's loop: ``{"cmd": "init", ...}`` makes the worker ``make(**cmd)``; any other
    command ``name`` calls ``handlers[name](worker, **cmd)``; "quit" (or the end) ends it."""
    # An editable install's finder would serve the installed checkout's modules that a tree lacks.
    sys.meta_path[:] = [f for f in sys.meta_path
                        if "editable" not in getattr(f, "__name__", type(f).__name__).lower()]
    worker = None
    for line in sys.stdin:
        cmd = json.loads(line)
        name = cmd.pop("cmd")
        if name == "quit":
            break
        try:
            if name == "init":
                worker = make(**cmd)
                import rodmol

                answer = dict(rodmol_file=rodmol.__file__)
            else:
                answer = handlers[name](worker, **cmd)
        except Exception as exc:  # noqa: BLE001  (hand any failure to the parent)
            import traceback

            answer = dict(error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
        sys.stdout.write(MARK + json.dumps(answer) + "\n")
        sys.stdout.flush()


class Version:
    """A worker subprocess (``script --worker``) running the rodmol of ``tree``."""

    def __init__(self, label, tree, script, stderr_path):
        env = dict(os.environ, PYTHONPATH=tree)
        for var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS"):
            env[var] = "1"
        self.label, self.tree = label, tree
        self._err = open(stderr_path, "w")  # noqa: SIM115  (open for the worker's lifetime)
        self.proc = subprocess.Popen([sys.executable, os.path.abspath(script), "--worker"], env=env,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._err,
                                     text=True, cwd=tree)

    def ask(self, **cmd):
        self.proc.stdin.write(json.dumps(cmd) + "\n")
        self.proc.stdin.flush()
        for line in self.proc.stdout:
            if line.startswith(MARK):
                answer = json.loads(line[len(MARK):])
                if "error" in answer:
                    raise RuntimeError(f"{self.label} worker: {answer['error']}\n{answer['traceback']}")
                return answer
        self._err.flush()
        with open(self._err.name) as f:
            raise RuntimeError(f"{self.label} worker exited:\n{f.read()[-4000:]}")

    def start(self, **cmd):
        """Initialise the worker (``init``), checking that it imported rodmol from its tree."""
        file = self.ask(cmd="init", **cmd)["rodmol_file"]
        if not os.path.realpath(file).startswith(os.path.realpath(self.tree) + os.sep):
            raise RuntimeError(f"{self.label} worker imported {file}, not from {self.tree}")
        return file

    def close(self):
        try:
            self.proc.stdin.write(json.dumps(dict(cmd="quit")) + "\n")
            self.proc.stdin.close()
            self.proc.wait(timeout=30)
        except Exception:  # noqa: BLE001  (a worker that will not quit is killed)
            self.proc.kill()
            self.proc.wait()
        self._err.close()


def paired_ratio(np, runs, key, new, base, pair="rep"):
    """Median over rounds of ``runs``' ``key`` of version ``new`` over version ``base`` (they ran
    back to back within a round: the ratio sees the same load)."""
    by = {}
    for r in runs:
        by.setdefault(r[pair], {})[r["version"]] = r[key]
    return float(np.median([d[new] / d[base] for d in by.values() if d.get(base)]))
