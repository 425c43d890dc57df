"""One run per output directory: a lock file holding the owner's host and pid.

Two runs writing into the same directory would mix their frames, and each
would delete the other's as stale. :class:`OutputLock` creates
``DIR/.rodmol.lock`` atomically (``O_CREAT | O_EXCL``); a second run finds it
and is refused with a message naming the owner. A lock left by a run that
died (its pid no longer exists on this host) is stale and taken over.
"""

import json
import os
import socket
from pathlib import Path

from ..errors import ParameterError

LOCK_NAME = ".rodmol.lock"


def _alive(pid):
    if not isinstance(pid, int) or pid <= 0:  # never signal a process group
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        return True
    except OSError:
        return False
    return True


class OutputLock:
    """Context manager holding the lock of output directory ``directory``."""

    def __init__(self, directory):
        self.path = Path(directory) / LOCK_NAME
        self.held = False

    def __enter__(self):
        self.acquire()
        return self

    def __exit__(self, *exc):
        self.release()

    def acquire(self):
        owner = {"host": socket.gethostname(), "pid": os.getpid()}
        for _ in range(3):  # a stale lock is removed and the creation retried
            try:
                fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                holder = self._holder()
                if holder is not None and self._stale(holder):
                    self.path.unlink(missing_ok=True)
                    continue
                raise ParameterError(self._busy(holder)) from None
            except OSError as exc:
                raise ParameterError(f"cannot lock the output directory {str(self.path.parent)!r}: "
                                     f"{exc.strerror}") from None
            with os.fdopen(fd, "w") as handle:
                json.dump(owner, handle)
            self.held = True
            return
        raise ParameterError(self._busy(self._holder()))

    def release(self):
        if self.held:
            self.path.unlink(missing_ok=True)
            self.held = False

    def _holder(self):
        """The owner recorded in the lock file, or None if it cannot be read yet."""
        try:
            holder = json.loads(self.path.read_text(encoding="utf-8"))
            return holder if isinstance(holder, dict) and isinstance(holder.get("pid"), int) else {}
        except FileNotFoundError:
            return {"pid": -1, "host": socket.gethostname()}  # gone meanwhile: stale
        except (OSError, ValueError):
            return {}  # unreadable or being written: treat as held

    @staticmethod
    def _stale(holder):
        return holder.get("host") == socket.gethostname() and not _alive(holder.get("pid", -1)) \
            if holder else False

    def _busy(self, holder):
        who = (f"pid {holder['pid']} on {holder.get('host', '?')}" if holder and "pid" in holder
               else "another process")
        return (f"another rodmol run ({who}) is writing into {str(self.path.parent)!r}: wait for it "
                f"or choose another --out (if no run is active, delete {str(self.path)!r})")
