"""Checks of the streamed XDMF views without ParaView: resolve the includes, and
check that every grid's hyperslab points at a frame that exists in its HDF5 file."""

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py

XI = "{http://www.w3.org/2001/XInclude}include"
SLAB = re.compile(r"(?P<file>[^:]+):/(?P<name>[^|]+)\|(?P<start>\d+) .*:(?P<dims>[\d ]+)$")


def view_grids(path):
    """The uniform grids of a view (``rod.xdmf``, ...), in order, with their includes resolved."""
    path = Path(path)
    name = ET.parse(path).getroot().find("Domain/Grid").get("Name")
    grids = []
    for include in ET.parse(path).getroot().iter(XI):
        fragment = ET.parse(path.parent / include.get("href")).getroot()
        collection = next(g for g in fragment.find("Domain") if g.get("Name") == name)
        grids.extend(collection.findall("Grid"))
    return grids


def assert_valid_views(directory, timed="rod.xdmf"):
    """Every view's grids point at existing frames of existing chunk files; returns the times of
    the view ``timed`` (the rod's; a system's directory: ``bodies.xdmf``)."""
    directory = Path(directory)
    times = None
    for view in sorted(directory.glob("*.xdmf")):
        grids = view_grids(view)
        assert grids, view
        for grid in grids:
            for item in grid.iter("DataItem"):
                text = item.text.strip()
                file = directory / text.split(":/")[0]
                assert file.is_file(), text
                match = SLAB.match(text)
                with h5py.File(file, "r") as handle:
                    dataset = handle[match["name"] if match else text.split(":/")[1]]
                    if match:
                        assert list(dataset.shape) == [int(d) for d in match["dims"].split()], text
                        assert int(match["start"]) < dataset.shape[0], text
        if view.name == timed:
            times = [float(g.find("Time").get("Value")) for g in grids]
    assert times is not None, f"no {timed}"
    return times
