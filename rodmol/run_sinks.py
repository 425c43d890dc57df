"""Where ``simulate(..., out=DIR)`` streams its frames: the directory sink that
the output package registers (:class:`rodmol.output.stream.RunWriter`, when
``rodmol`` is imported), so that :func:`rodmol.simulate` builds one without
importing the floors above it. The sink protocol is
:mod:`rodmol.solve.chunked`'s."""

_factory = []  # the one registered factory: (directory, resume=, overwrite=) -> sink
_system_factory = []  # (directory, resume=, overwrite=) -> sink, for a System's out=DIR


def register_directory(factory):
    """Make ``factory(directory, resume=bool, overwrite=bool)`` the sink of ``out=DIR``."""
    _factory[:] = [factory]


def directory_sink(directory, *, resume, overwrite):
    """The registered sink streaming into ``directory`` (see :func:`register_directory`)."""
    if not _factory:
        raise RuntimeError("no directory sink is registered: import rodmol (rodmol.output.stream registers it)")
    return _factory[0](directory, resume=resume, overwrite=overwrite)


def register_system_writer(factory):
    """Make ``factory(directory, resume=bool, overwrite=bool)`` the sink of a System's ``out=DIR``
    (the protocol of :mod:`rodmol.solve.chunked`, its frames the assembled states)."""
    _system_factory[:] = [factory]


def system_writer(directory, *, resume, overwrite):
    """The registered sink of a System's run into ``directory`` (see :func:`register_system_writer`)."""
    if not _system_factory:
        raise RuntimeError("no system writer is registered: import rodmol (rodmol.output.system_stream registers it)")
    return _system_factory[0](directory, resume=resume, overwrite=overwrite)
