"""What a run writes and how it is read back: the formats' registry
(:mod:`rodmol.output.formats`), the streamed run directory
(:mod:`rodmol.output.stream`: ``result.h5`` and the XDMF views), the VTK series
(:mod:`rodmol.output.writers`), :func:`~rodmol.output.formats.load_result` and the
pictures (:mod:`rodmol.output.pictures`)."""
