"""Writing a file so that readers only ever see a complete one."""

import contextlib
import os
import tempfile


def _umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_atomically(path, write):
    """Call ``write(handle)`` on a binary file, then move it to ``path``.

    The file is written under a unique temporary name in the same folder and
    renamed with :func:`os.replace`: a half-written file never sits under the
    real name (a full disk or an interrupt leave the previous version), and
    two writers never share a temporary. The temporary is removed on error.
    """
    path = os.fspath(path)
    folder, name = os.path.split(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".part", dir=folder)
    try:
        with os.fdopen(fd, "wb") as handle:
            write(handle)
        os.chmod(tmp, 0o666 & ~_umask())  # as an ordinary open() would have made it
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
