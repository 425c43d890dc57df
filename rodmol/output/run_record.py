"""What the index of a streamed run records besides its frames: the settings
the run was made with (:mod:`rodmol._settings`), the solver's work for each
chunk kept, and the run's sessions (the first one and each resume).

The run's statistics (``Result.stats``) count the work of the chunks kept:
``steps``, ``rhs_evals``, ``jac_evals``, ``prec_setups``, ``prec_solves``
and ``wall_time_s`` (integration) are summed over them, whatever session
computed them, so a resumed run reports the steps the uninterrupted run
took; ``prepare_s`` and ``equilibrium_s`` are summed over the sessions.
After a resume, ``stats["resumed_at"]`` is the time [s] the last session
started from and ``stats["sessions"]`` lists every session (``t_start``,
``t_end`` [s], its own ``steps``, ``rhs_evals``, ``jac_evals``,
``wall_time_s``, ``prepare_s``, ``equilibrium_s``, and ``forced``, the
settings a forced resume changed): a session's work includes a chunk it
began that a later resume redid.
"""

from contextlib import contextmanager

from ..errors import ParameterError
from ..solve.outputs import merge_stats

#: The statistics of a session (its entry of ``stats["sessions"]``).
SESSION_KEYS = ("steps", "rhs_evals", "jac_evals", "wall_time_s", "prepare_s", "equilibrium_s")
#: Statistics of the sessions' preparation, summed over them.
STAGES = ("prepare_s", "equilibrium_s")


class RunRecord:
    """The record of a run, read back from its index's ``info`` (None: a new run)."""

    def __init__(self, info=None):
        info = info or {}
        self.settings = info.get("settings")
        self.work = dict(info.get("chunk_stats") or {})
        self.sessions = list(info.get("sessions") or [])
        # An index of an older rodmol holds only the merged statistics of its run.
        self.legacy = info.get("stats") if info and "chunk_stats" not in info else None
        self.parts, self.pending, self.forced, self.t_start = [], None, [], None

    def account(self, stats):
        """The solver's statistics of the frames stored next (:func:`rodmol.solve.chunked.run_chunked`)."""
        self.pending = dict(stats)

    def stored(self, name):
        """The chunk ``name`` holds the frames accounted last."""
        if self.pending is not None:
            self.work[name], self.pending = self.pending, None
            self.parts.append(self.work[name])

    def drop(self, names):
        for name in names:
            self.work.pop(name, None)

    def info(self, chunks, t_end, stats=None):
        """The index's record after the frames up to ``t_end`` [s] in ``chunks``; ``stats``: this
        session's statistics once it ended (None while it runs)."""
        session = dict(t_start=self.t_start, t_end=t_end)
        mine = merge_stats(self.parts) if stats is None else stats
        session.update({key: mine[key] for key in SESSION_KEYS if key in mine})
        if self.forced:
            session["forced"] = self.forced
        sessions = [*self.sessions, session]
        kept = {name: self.work[name] for name in chunks if name in self.work}
        whole = dict(stats or {})
        if self.legacy is not None:
            whole = merge_stats([self.legacy, whole])
        elif kept:
            whole.update(merge_stats(list(kept.values())))
        if len(sessions) > 1:
            for key in STAGES:
                if any(key in s for s in sessions):
                    whole[key] = sum(s.get(key, 0.0) for s in sessions)
            whole.update(resumed_at=sessions[-1]["t_start"], sessions=sessions)
        return dict(settings=self.settings, chunk_stats=kept, sessions=sessions, stats=whole)


@contextmanager
def damaged(path):
    """Turn a failure to read the file ``path`` of a run being resumed into a ParameterError."""
    try:
        yield
    except (OSError, KeyError, ValueError, TypeError, IndexError) as exc:
        raise ParameterError(f"cannot resume from {str(path)!r}: the file is damaged, truncated or not "
                             f"rodmol's ({type(exc).__name__}: {exc}); start the run again "
                             "(`rodmol run ... --overwrite`, simulate(..., overwrite=True))") from None
