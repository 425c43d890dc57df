"""Writing a file so that readers only ever see a complete one."""

import contextlib
import os
import tempfile


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; moved to ``path`` when the block ends normally.

    The file is written under a unique temporary name in the same folder and
    renamed with :func:`os.replace`: a half-written file never sits under the
    real name (a full disk or an interrupt leave the previous version), and
    two writers never share a temporary. The temporary is removed on error.
    """
    path = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".part", dir=folder)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_umask())  # as an ordinary open() would have made it
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def write_atomically(path, write):
    """Call ``write(handle)`` on a binary file, then move it to ``path`` (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        write(handle)
