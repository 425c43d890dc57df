"""Helpers of the output tests: a streamed run killed between two chunks."""

import pytest

from rodmol.output.stream import RunWriter


class Killed(BaseException):
    """Stands for a SIGKILL between two chunks, once the chunks before are on disk."""


class DiesAfter(RunWriter):
    def __init__(self, directory, chunks, **options):
        super().__init__(directory, **options)
        self.left = chunks

    def frames(self, t, y):
        if self.left == 0:
            self.flush()
            raise Killed
        self.left -= 1
        super().frames(t, y)


@pytest.fixture
def killed():
    """``killed(run, directory, chunks, **writer_options)``: call ``run(out=sink)`` with a sink
    (a RunWriter into ``directory``) killed once ``chunks`` chunks are on disk."""

    def kill(run, directory, chunks, **options):
        with pytest.raises(Killed):
            run(out=DiesAfter(directory, chunks, **options))

    return kill
