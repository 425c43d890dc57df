"""ParaView collections (``.pvd``) that grow at a cost proportional to what is added.

A collection lists ``(time [s], file)`` entries between the opening and the
closing tags of its XML. Written anew at every flush, a long series would
cost O(frames^2) in all (0.79 s a rewrite at 60,001 frames). A
:class:`Collection` instead keeps room, blank space inside the
``<Collection>`` element, between its last entry and the closing tags, and
writes the new entries into it, one page (:data:`PAGE` bytes, aligned) per
system call, never an entry across a page boundary. A process is killed
between two such writes or before one, never inside one, so the file is
valid XML listing complete entries at every moment a run can be killed. When
the room is used up, the whole collection is written again (atomically)
with as much room as its entries take, so the rewrites cost O(frames) in
all; :meth:`Collection.close` writes it once more without room.
"""

import contextlib
import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .._files import write_atomically

HEAD = (b"<?xml version='1.0' encoding='utf-8'?>\n"
        b'<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n  <Collection>\n')
TAIL = b"  </Collection>\n</VTKFile>\n"
#: The unit a write to a file's page cache is not split within (a larger page holds whole ones).
PAGE = 4096
#: The room a new collection keeps for its first entries [bytes].
FIRST_ROOM = 4 * PAGE


def entry(t, file):
    """One entry's line: the frame at time ``t`` [s] in ``file`` (relative to the collection)."""
    return (f"    <DataSet timestep={quoteattr(repr(float(t)))} group=\"\" part=\"0\" "
            f"file={quoteattr(str(file))} />\n").encode()


def write_pvd(path, entries, room=0):
    """Write a collection listing ``(time [s], file)`` entries, atomically, with ``room`` blank
    bytes before its closing tags; returns the offset of the room."""
    body = HEAD + b"".join(entry(t, file) for t, file in entries)
    write_atomically(path, lambda handle: handle.write(body + b" " * room + TAIL))
    return len(body)


def read_pvd(path):
    """``(time [s], absolute path)`` entries of a ``.pvd`` collection."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    folder = Path(path).parent
    return [(float(d.get("timestep")), folder / d.get("file")) for d in root.iter("DataSet")]


class Collection:
    """A ``.pvd`` collection at ``path`` (replaced by an empty one) that entries are added to.

    :meth:`add` queues an entry; :meth:`flush` writes the queued ones into the
    file (see the module); :meth:`close` flushes and leaves the file without
    room. ``written`` counts the bytes written to the file [bytes], ``rewrites`` the times it
    was written whole.
    """

    def __init__(self, path):
        self.path = Path(path)
        self.entries, self.queued, self.written, self.rewrites = [], [], 0, 0
        self._rewrite(FIRST_ROOM)

    def add(self, t, file):
        """Queue the entry of the frame at time ``t`` [s] in ``file`` (relative to the collection)."""
        self.queued.append((float(t), str(file)))

    def flush(self):
        """Write the queued entries into the file."""
        if not self.queued:
            return
        lines = [entry(t, file) for t, file in self.queued]
        # At most twice their length: an entry moved to the next page leaves less than itself blank.
        if self._at + 2 * sum(map(len, lines)) > self._end:
            self.entries += self.queued
            self.queued = []
            self._rewrite(max(FIRST_ROOM, self._end))  # as much room as the file holds: O(frames) in all
            return
        batches, at = [], self._at
        for line in lines:
            if at // PAGE != (at + len(line) - 1) // PAGE:  # never across a page: the rest stays blank
                at = (at // PAGE + 1) * PAGE
            if not batches or batches[-1][0] // PAGE != at // PAGE:
                batches.append([at, b""])
            batches[-1][1] += line
            at += len(line)
        fd = os.open(self.path, os.O_WRONLY)
        try:
            for offset, data in batches:
                if os.pwrite(fd, data, offset) != len(data):
                    raise OSError(f"a short write to {str(self.path)!r} (disk full?)")
                self.written += len(data)
        except OSError:
            with contextlib.suppress(OSError):  # blank the batches again: what was written is valid
                for offset, data in batches:
                    os.pwrite(fd, b" " * len(data), offset)
            raise
        finally:
            os.close(fd)
        self.entries += self.queued
        self.queued, self._at = [], at

    def close(self):
        """Flush, and write the collection without room."""
        self.flush()
        self.entries += self.queued
        self.queued = []
        self._rewrite(0)

    def _rewrite(self, room):
        """Write the whole collection anew with ``room`` blank bytes for the entries to come."""
        self._at = write_pvd(self.path, self.entries, room)
        self._end = self._at + room
        self.written += self._end + len(TAIL)
        self.rewrites += 1
