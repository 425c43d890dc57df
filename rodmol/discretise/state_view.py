"""A read-only view of one state vector: what feedback tensions, the stepping
simulator and the environments read of the rod (:class:`StateView`)."""

from . import centreline, rotations


class StateView:
    """Read-only view of a state vector, handed to feedback tensions.

    Attributes are computed on access: ``t`` [s], ``positions`` (N+1, 3) [m]
    global (rebuilt from the strains, as ``Result.positions``), ``tip`` (3,)
    [m], ``rotations`` (N+1, 3, 3), ``q``, ``k``, ``v``, ``w`` (N, 3) local;
    from :meth:`SemiDiscrete.state_view` also ``cable_lengths`` (n_cables,) [m]
    and ``markers`` (n_markers, 3) [m] global, as ``Result.markers``.
    """

    def __init__(self, layout, t, y, ds, routing=None, model=None):
        self.t, self._layout, self._y, self._ds, self._routing = t, layout, y, ds, routing
        self._model = model  # whose markers are tracked

    def cable_length(self, name):
        """Path length [m] of the cable called ``name`` from the base to its anchor."""
        if self._routing is None:
            raise AttributeError("cable lengths need the system's routing (SemiDiscrete.state_view)")
        return float(self.cable_lengths[self._routing.index[name]])

    def __getattr__(self, name):
        value = self._compute(name)
        self.__dict__[name] = value  # once per view: laws read the same attribute repeatedly
        return value

    def _compute(self, name):
        if name == "cable_lengths":
            return self._routing.lengths(self.q, self.k)
        if name in ("q", "k", "v", "w"):
            return self._layout.field(self._y, name)
        if name == "rotations":
            return rotations.matrices(self._layout.quaternions(self._y))
        if name == "positions":
            return centreline.positions(self._layout.base_position(self._y),
                                        self._layout.quaternions(self._y), self.q, self.k, self._ds)
        if name == "tip":
            return self.positions[-1]
        if name == "markers" and self._model is not None:
            m = self._model
            return centreline.track([mk.s for mk in m.markers], m.marker_offsets[:, 1:], m.s_nodes,
                                    self.positions[None], self.rotations[None])[0]
        raise AttributeError(name)
