"""Where ``simulate(..., out=DIR)`` streams its frames: the directory sink that
the output package registers (:class:`rodmol.output.stream.RunWriter`, when
``rodmol`` is imported), so that :func:`rodmol.simulate` builds one without
importing the floors above it. The sink protocol is
:mod:`rodmol.solve.chunked`'s."""

_factory = []  # the one registered factory: (directory, resume=, overwrite=) -> sink


def register_directory(factory):
    """Make ``factory(directory, resume=bool, overwrite=bool)`` the sink of ``out=DIR``."""
    _factory[:] = [factory]


def directory_sink(directory, *, resume, overwrite):
    """The registered sink streaming into ``directory`` (see :func:`register_directory`)."""
    if not _factory:
        raise RuntimeError("no directory sink is registered: import rodmol (rodmol.output.stream registers it)")
    return _factory[0](directory, resume=resume, overwrite=overwrite)
