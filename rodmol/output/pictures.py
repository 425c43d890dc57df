"""Pictures of a result: off-screen 3-D renders (pyvista) and time plots (matplotlib)."""

from pathlib import Path

import numpy as np

from .._files import claim, output_directory
from .run_files import PLOTTED, RENDERED


def render(result, directory, size=(960, 720), frames=60, progress=None, overwrite=False):
    """Render ``last_frame.png`` and (``frames`` > 0) ``animation.gif`` into ``directory``.

    Off-screen pyvista: the body as a tube of the true radius coloured by the
    bending curvature, the cables as lines (red when pulled), the markers as dots;
    of a SystemResult, every rod so and every rigid body as its surface
    (:func:`rodmol.output.system_files.body_surface`).
    ``progress``: a ``rodmol._progress.Progress`` showing the frames drawn.
    Earlier pictures there are kept unless ``overwrite`` (:func:`rodmol._files.claim`:
    refused before anything is drawn; with ``overwrite`` both are removed first).
    """
    directory = output_directory(directory, "directory")
    claim([directory / name for name in RENDERED], overwrite)
    import pyvista as pv
    from PIL import Image

    from .writers import cables_mesh, frame_indices, markers_mesh, rod_mesh

    pv.OFF_SCREEN = True
    _quiet_vtk()
    rods, bodies = _parts(result)
    bending = [np.linalg.norm(rod.curvature[..., 1:], axis=-1) for rod in rods]
    top = max(max(float(b.max()) for b in bending), 1e-9)
    r_max = max(float(np.max(rod.radius)) for rod in rods)
    points = [rod.positions.reshape(-1, 3) for rod in rods] + [_placed(body, surface, slice(None)).reshape(-1, 3)
                                                             for body, surface in bodies]
    low = np.min([p.min(axis=0) for p in points], axis=0) - r_max
    high = np.max([p.max(axis=0) for p in points], axis=0) + r_max
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")

    def draw(k):  # render=False: one render per frame, not one per part (each costs ~0.1 s off-screen)
        for i, part in enumerate(rods):
            rod = rod_mesh(part, k)
            rod.point_data["bending curvature [1/m]"] = bending[i][k]
            plotter.add_mesh(rod.tube(scalars="radius [m]", absolute=True, n_sides=32), name=f"body {i}",
                             scalars="bending curvature [1/m]", clim=[0.0, top], cmap="viridis",
                             smooth_shading=True, opacity=0.55, scalar_bar_args=dict(color="black"), render=False)
            cables = cables_mesh(part, k)
            if cables.n_cells:
                pulled = cables.cell_data["tension [N]"] > 0
                colours = np.where(pulled[:, None], [[0.85, 0.1, 0.1]], [[0.6, 0.6, 0.6]])
                cables.cell_data["colour"] = (255 * colours).astype(np.uint8)
                plotter.add_mesh(cables, name=f"cables {i}", scalars="colour", rgb=True, line_width=3,
                                 render=False)
            if len(part.meta.get("markers", [])):
                plotter.add_mesh(markers_mesh(part, k), name=f"markers {i}", color="black", point_size=10,
                                 render_points_as_spheres=True, render=False)
        for i, (body, (corners, triangles)) in enumerate(bodies):
            faces = np.hstack([np.full((len(triangles), 1), 3), triangles]).ravel()
            plotter.add_mesh(pv.PolyData(_placed(body, (corners, triangles), k), faces), name=f"rigid {i}",
                             color=(0.8, 0.55, 0.35), smooth_shading=False, render=False)
        plotter.add_text(f"t = {result.t[k]:.2f} s", name="time", color="black", font_size=12, render=False)

    draw(len(result.t) - 1)
    centre, extent = (low + high) / 2, float(np.linalg.norm(high - low))
    direction = np.array([0.25, 0.45, 1.0]) / np.linalg.norm([0.25, 0.45, 1.0])  # from front, above
    plotter.camera_position = [tuple(centre + 2 * extent * direction), tuple(centre), (0.0, 1.0, 0.0)]
    plotter.reset_camera(bounds=[low[0], high[0], low[1], high[1], low[2], high[2]])
    plotter.camera.zoom(1.3)
    written = [Path(directory) / RENDERED[0]]
    plotter.screenshot(written[0])
    if frames > 0 and len(result.t) > 1:
        every = max(1, int(np.ceil(len(result.t) / frames)))
        indices = frame_indices(len(result.t), every)
        images = []
        for k in progress.frames(indices, len(indices), "rendering") if progress else indices:
            draw(k)  # the screenshot renders it
            images.append(Image.fromarray(plotter.screenshot(return_img=True)))
        step_ms = max(20, int(round(1000 * (result.t[-1] - result.t[0]) / max(len(indices) - 1, 1))))
        written.append(Path(directory) / RENDERED[1])
        images[0].save(written[1], save_all=True, append_images=images[1:], duration=step_ms, loop=0)
    plotter.close()
    return written


def _parts(result):
    """(the rods' Results, [(BodyResult, its surface)]) of a Result or a SystemResult."""
    from .system_files import surface_of

    if not hasattr(result, "bodies"):
        return [result], []
    return [result[name] for name in result.rods], [(result[name], surface_of(result, name))
                                                   for name in result.bodies]


def _placed(body, surface, k):
    """The body's surface points at frame(s) ``k`` [m], global."""
    points = surface[0]
    return body.position[k, ..., None, :] + np.einsum("...ij,pj->...pi", body.rotation[k], points)


def _quiet_vtk():
    """Hide VTK's console warnings (it first tries an X display, then falls back to EGL)."""
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)


def plot(result, directory, overwrite=False):
    """Tip and marker paths, marker positions vs time and tensions vs time, as PNGs in
    ``directory`` (like the paper's Figs. 7-8); returns their paths. Earlier plots there are
    kept unless ``overwrite`` (:func:`rodmol._files.claim`)."""
    directory = output_directory(directory, "directory")
    claim([directory / name for name in PLOTTED], overwrite)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    directory, written = Path(directory), []
    if hasattr(result, "bodies"):
        return _plot_system(result, directory)
    names = [m["name"] for m in result.meta.get("markers", [])]

    fig, axes = plt.subplots(1, 2, figsize=(11, 5), constrained_layout=True)
    for ax, (i, j) in zip(axes, ((0, 1), (0, 2))):
        ax.plot(result.tip[:, i], result.tip[:, j], "k-", lw=1.5, label="tip")
        for m, name in enumerate(names):
            ax.plot(result.markers[:, m, i], result.markers[:, m, j], lw=1, label=f"marker {name}")
        ax.plot(result.positions[-1, :, i], result.positions[-1, :, j], ":", color="grey", label="last frame")
        ax.set(xlabel=f"{'xyz'[i]} [m]", ylabel=f"{'xyz'[j]} [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Paths, global frame")
    written.append(_save(fig, directory / PLOTTED[0]))

    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True, constrained_layout=True)
    for i, ax in enumerate(axes):
        ax.plot(result.t, result.tip[:, i], "k-", lw=1.5, label="tip")
        for m, name in enumerate(names):
            ax.plot(result.t, result.markers[:, m, i], lw=1, label=name)
        ax.set(ylabel=f"{'xyz'[i]} [m]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, ncol=5)
    axes[-1].set(xlabel="t [s]")
    fig.suptitle("Marker positions, global frame")
    written.append(_save(fig, directory / PLOTTED[1]))

    fig, ax = plt.subplots(figsize=(8, 3.5), constrained_layout=True)
    cables = [c["name"] for c in result.meta.get("cables", [])]
    pulled = [i for i in range(len(cables)) if np.any(result.tensions[:, i] > 0)]
    for i in pulled:
        ax.plot(result.t, result.tensions[:, i], label=cables[i])
    ax.set(xlabel="t [s]", ylabel="tension [N]", title="Cable tensions" + ("" if pulled else " (all slack)"))
    ax.grid(alpha=0.3)
    if pulled:
        ax.legend(fontsize=8)
    written.append(_save(fig, directory / PLOTTED[2]))
    return written


def _plot_system(result, directory):
    """:func:`plot` of a SystemResult: the rods' tip paths and the bodies' paths,
    the bodies' positions vs time, every cable's tension vs time."""
    import matplotlib.pyplot as plt

    rods, bodies = {n: result[n] for n in result.rods}, {n: result[n] for n in result.bodies}
    fig, axes = plt.subplots(1, 2, figsize=(11, 5), constrained_layout=True)
    for ax, (i, j) in zip(axes, ((0, 1), (0, 2))):
        for name, rod in rods.items():
            ax.plot(rod.tip[:, i], rod.tip[:, j], lw=1, label=f"{name} tip")
            ax.plot(rod.positions[-1, :, i], rod.positions[-1, :, j], ":", color="grey")
        for name, body in bodies.items():
            ax.plot(body.position[:, i], body.position[:, j], "k-", lw=2, label=name)
        ax.set(xlabel=f"{'xyz'[i]} [m]", ylabel=f"{'xyz'[j]} [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Paths, global frame (dotted: the rods at the last frame)")
    written = [_save(fig, directory / PLOTTED[0])]

    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True, constrained_layout=True)
    for i, ax in enumerate(axes):
        for name, body in bodies.items():
            ax.plot(result.t, body.position[:, i], lw=1.5, label=name)
        ax.set(ylabel=f"{'xyz'[i]} [m]")
        ax.grid(alpha=0.3)
    if bodies:
        axes[0].legend(fontsize=8, ncol=5)
    axes[-1].set(xlabel="t [s]")
    fig.suptitle("Body positions (origin), global frame")
    written.append(_save(fig, directory / PLOTTED[1]))

    fig, ax = plt.subplots(figsize=(8, 3.5), constrained_layout=True)
    pulled = 0
    for name, rod in rods.items():
        for i, cable in enumerate(rod.meta.get("cables", [])):
            if np.any(rod.tensions[:, i] > 0):
                ax.plot(result.t, rod.tensions[:, i], label=f"{name}: {cable['name']}")
                pulled += 1
    ax.set(xlabel="t [s]", ylabel="tension [N]", title="Cable tensions" + ("" if pulled else " (all slack)"))
    ax.grid(alpha=0.3)
    if pulled:
        ax.legend(fontsize=7, ncol=2)
    written.append(_save(fig, directory / PLOTTED[2]))
    return written


def _save(fig, path):
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
