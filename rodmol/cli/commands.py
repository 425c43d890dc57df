"""The ``rodmol`` command line: run scenario files, render and plot results.

    rodmol run SCENARIO.toml [--out DIR] [--backend NAME] [--n-elements N] [--scheme NAME]
               [--t-end T] [--format xdmf|vtp] [--resume | --resume-anyway | --overwrite] [--quiet]
    rodmol run --example fetching [--out DIR] ...
    rodmol render DIR        # last_frame.png and animation.gif from DIR (result.h5 or result.npz)
    rodmol plot DIR          # tip_path.png, markers.png, tensions.png
    rodmol study | identify | sweep ...   # calibration (see rodmol.cli.calibrate)

Options are never abbreviated. A run in ``--out`` is never replaced without
``--overwrite`` (:mod:`rodmol.output.run_files`); ``--resume`` continues it with
the settings it recorded (:mod:`rodmol._settings`).

Exit codes: 0 done, 1 the solver failed, 2 bad scenario or arguments (or the
output directory is in use by another run), 3 outputs could not be written
(what was written is valid), 130 interrupted (Ctrl-C), 143 terminated
(SIGTERM). A signal stops a run, a rod's or a system's alike, at the end of
its current step (a second Ctrl-C stops it at once); the run keeps the
frames done and, streamed, continues with ``--resume``.
"""

import argparse
import signal
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

from .._files import output_directory
from .._progress import Progress
from .._version import __version__
from ..errors import ParameterError, RodmolError
from ..output import h5result
from ..output.formats import FORMATS, get_format
from ..output.lock import OutputLock
from ..output.run_files import cannot_write
from ..output.system_files import INDEX as SYSTEM_INDEX
from ..output.system_stream import SystemRunWriter
from ..solve.interrupts import DeferredSignals
from ..systems import System
from .options import EXAMPLES, add_run_options, load_spec

EXIT_FAILED, EXIT_USAGE, EXIT_OUTPUT, EXIT_INTERRUPTED = 1, 2, 3, 130
#: Exit code of a run stopped by each signal (128 + the signal's number, as a shell reports it).
EXIT_SIGNAL = {signal.SIGINT: 130, signal.SIGTERM: 143}
#: Said at the first signal: the run goes on to its next safe point (a step's end), then stops.
STOPPING = "rodmol: stopping after the solver's current step (Ctrl-C again to stop at once)"
__all__ = ["Progress", "main", "stopped", "summary"]


def main(argv=None):
    """Entry point of the ``rodmol`` command; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        return args.command(args)
    except ParameterError as exc:
        print(f"rodmol: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except RodmolError as exc:  # e.g. no equilibrium to start from: the run could not start
        print(f"rodmol: error: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print("rodmol: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _parser():
    parser = _Parser(prog="rodmol", description="Soft cable-driven arms as Cosserat rods.")
    parser.add_argument("--version", action="version", version=f"rodmol {__version__}")
    commands = parser.add_subparsers(required=True, metavar="COMMAND")

    run = commands.add_parser("run", help="run a scenario file, streaming result.h5 and ParaView views")
    run.add_argument("scenario", nargs="?", help="TOML scenario file (see docs/scenario-reference.md)")
    run.add_argument("--example", choices=EXAMPLES, metavar="NAME", help="run one of the paper's tests instead of a file: "
                                                                  + ", ".join(EXAMPLES))
    add_run_options(run)
    run.set_defaults(command=_run)

    example = commands.add_parser("example", help="run one of the paper's tests without a file")
    example.add_argument("example", choices=EXAMPLES)
    add_run_options(example)
    example.set_defaults(command=_run, scenario=None)

    render = commands.add_parser("render", help="render the last frame (PNG) and an animation (GIF)")
    render.add_argument("directory", type=Path, help="output directory of `rodmol run` (or its result file)")
    render.add_argument("--frames", type=int, default=60, help="animation frames (default 60; 0: none)")
    render.add_argument("--size", default="960x720", help="picture size in pixels, WxH (default 960x720)")
    _overwrite_option(render, "pictures")
    render.set_defaults(command=_render)

    plot = commands.add_parser("plot", help="plot tip path, markers and tensions vs time (PNG)")
    plot.add_argument("directory", type=Path, help="output directory of `rodmol run` (or its result file)")
    _overwrite_option(plot, "plots")
    plot.set_defaults(command=_plot)

    from .calibrate import add_commands

    add_commands(commands)
    return parser


def _overwrite_option(parser, what):
    parser.add_argument("--overwrite", action="store_true", help=f"replace the {what} drawn there earlier "
                        "(without it they are kept and the command refused)")


class _Parser(argparse.ArgumentParser):
    """A parser that takes no abbreviated options (argparse would take ``--n-element`` for
    ``--n-elements``); the subcommands' parsers are of the same class (``add_subparsers``
    makes them with the class of their parent)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, allow_abbrev=False, **kwargs)


# --------------------------------------------------------------------------- run

def _run(args):
    spec = load_spec(args)
    out = args.out or spec.output.directory or Path("out") / spec.name
    output_directory(out, "--out")  # before the run, so a directory that cannot be made does not waste it
    args.resume = "force" if args.resume_anyway else bool(args.resume)
    if args.resume and args.overwrite:
        raise ParameterError("give either `--resume` or `--overwrite`, not both")
    system = isinstance(spec.model, System)
    streamed = system or get_format(args.format or spec.output.format).sink is not None
    # One signal path for a rod's run and a system's: a signal asks the run to stop at its next
    # safe point (rodmol.solve.interrupts), which leaves its files whole and resumable.
    with OutputLock(out), DeferredSignals(EXIT_SIGNAL, notice=STOPPING) as signals:  # one run per directory
        try:
            code, result = (_run_system if system else _run_rod)(args, spec, out, signals)
        except KeyboardInterrupt:  # a second signal: stopped at once, the files as a kill leaves them
            if signals.signal is None:
                raise
            code, result = None, None
    if signals.signal is None:
        return code
    print(stopped(signals.signal, out, result, streamed), file=sys.stderr)
    return EXIT_SIGNAL[signals.signal]


def stopped(signum, out, result, streamed):
    """What a run stopped by the signal ``signum`` left in ``out``: whether and how it continues.
    ``result``: the run's (None: stopped at once, by a second signal)."""
    what = f"rodmol: {'interrupted' if signum == signal.SIGINT else 'terminated'} ({signum.name})"
    if result is not None and result.success:
        return f"{what} after the run had finished: {out} holds the whole run"
    if not streamed:
        return (f"{what}: the frames written are in {out} (a run written as `--format vtp` cannot be "
                "resumed; as `--format xdmf` it can)")
    if not any((Path(out) / index).is_file() for index in (h5result.INDEX, SYSTEM_INDEX)):
        return f"{what} before its first frame was written: nothing to resume, run it again"
    reached = "" if result is None or not len(result.t) else f" to t = {float(result.t[-1]):g} s"
    return (f"{what}: the run in {out} is kept{reached} and can be resumed: run the same command with "
            "`--resume` to continue it from its last complete chunk")


def _run_system(args, spec, out, signals):
    """``rodmol run`` of a system file: the run, its files streamed while it goes (``--resume``
    continues a killed one with its recorded settings, ``--resume-anyway`` with the file's);
    returns (exit code, result). ``signals`` is not needed: all its files are written while it goes."""
    if (args.format or spec.output.format) != "xdmf":
        raise ParameterError("a system's run is written as `--format xdmf` only")
    say = (lambda *a, **k: None) if args.quiet else print
    system = spec.model
    say(f"rodmol: {spec.name}: {len(system.rods)} rods, {len(system.bodies)} bodies, t_end = {spec.t_end:g} s, "
        f"{spec.solver['scheme']} scheme -> {out}")
    sink = out
    if not args.resume:  # the file's chunks and views (a resumed run keeps its own)
        chunk_frames = spec.output.chunk_frames if args.chunk_frames is None else args.chunk_frames
        sink = SystemRunWriter(out, chunk_frames=chunk_frames, every=spec.output.every, overwrite=args.overwrite)
    progress = None if args.quiet else Progress(stream=sys.stdout)
    started = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the summary gives the message
        result = spec.simulate(progress=progress, out=sink, resume=args.resume)
    if progress:
        progress.close()
    state = "finished" if result.success else f"stopped: {result.message}"
    reached = f" to t = {result.t[-1]:g} s" if len(result.t) else ""
    summary = (f"rodmol: {spec.name}: {state}; {len(result.t)} output frames{reached} in "
               f"{time.perf_counter() - started:.3g} s, written to {out} (open bodies.xdmf and NAME/rod.xdmf)")
    if result.success:
        say(summary)  # --quiet: nothing but errors
    else:
        print(summary, file=sys.stderr)
    return (0 if result.success else EXIT_FAILED), result


def _run_rod(args, spec, out, signals):
    """``rodmol run`` of a single rod's file; returns (exit code, result)."""
    from ..output.run_files import refuse_replacing

    say = (lambda *a, **k: None) if args.quiet else print
    if not args.resume:
        refuse_replacing(out, args.overwrite, "`--resume`", "`--overwrite`")
    model = spec.model
    writer = _stream_writer(args, spec, out)
    say(f"rodmol: {spec.name}: N = {model.n_elements} elements, t_end = {spec.t_end:g} s, "
        f"{spec.solver['scheme']} scheme, backend {spec.solver['backend']} -> {out}")
    if args.resume:
        frame, t_restart, _ = writer.restart
        say(f"rodmol: resuming the run in {out} at t = {t_restart:g} s (frame {frame} of {len(writer.t_out) - 1}, "
            "its last complete chunk)")
    try:
        progress = None if args.quiet else Progress(stream=sys.stdout)
        started = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # the summary gives the message
            result = spec.simulate(progress=progress, **({} if writer is None else
                                                         dict(out=writer, resume=args.resume)))
        wall = time.perf_counter() - started
        if progress:
            progress.close()
        signals.forcing = False  # from here, a signal stops writing between frames
        if writer is not None:  # written while the run went
            wall -= writer.seconds
            written = _streamed(writer, result)
        else:
            result.meta.update(scenario=spec.source, name=spec.name)
            say(f"rodmol: writing {len(result.t)} frames to {out} (Ctrl-C stops between frames) ...")
            options = replace(spec.output, format=args.format or spec.output.format)
            written = _write_outputs(result, options, out, signals)
            written["seconds"] = time.perf_counter() - started - wall
    except OSError as exc:  # the streamed index could not be replaced: the previous one is valid
        if writer is None:
            raise
        print(f"rodmol: {cannot_write(out / h5result.INDEX, exc)}", file=sys.stderr)
        return EXIT_OUTPUT, None
    if not args.quiet:
        print(summary(spec, result, wall, written))
    elif not result.success:
        print(f"rodmol: {spec.name}: {result.message}", file=sys.stderr)
    if "error" in written:
        print(f"rodmol: {written['error']}", file=sys.stderr)
        return EXIT_OUTPUT, result
    return (0 if result.success else EXIT_FAILED), result


def _stream_writer(args, spec, out):
    """The sink of a streamed run (a format with a sink, :mod:`rodmol.output.formats`), else None."""
    fmt = get_format(args.format or spec.output.format)
    options = spec.output
    if fmt.sink is None:
        if args.resume:
            raise ParameterError("`--resume` and `--resume-anyway` need the streamed output (--format "
                                 + " or ".join(f.name for f in FORMATS.values() if f.sink) + ")")
        fmt.before_run(out, options)  # before the run
        return None
    chunk_frames = options.chunk_frames if args.chunk_frames is None else args.chunk_frames
    return fmt.sink(out, views=options.vtk, every=options.every, chunk_frames=chunk_frames,
                    resume=bool(args.resume), overwrite=bool(args.overwrite),
                    meta=dict(scenario=spec.source, name=spec.name))


def _streamed(writer, result):
    # Absolute: given a bare file name, ParaView 5.11 looks for the included files in the wrong place.
    views = [(writer.directory / f"{v}.xdmf").resolve() for v in writer.view_names()] if writer.views else []
    written = dict(result=writer.directory / h5result.INDEX, views=views, seconds=writer.seconds,
                   frames=len(result.t))
    if isinstance(result.error, OSError):
        written["error"] = cannot_write(writer.directory / h5result.FRAMES, result.error)
    return written


def _write_outputs(result, options, out, signals):
    """Write the outputs of ``options.format`` after the run; stop between frames on a new signal
    (``signals``: the run's :class:`~rodmol.solve.interrupts.DeferredSignals`)."""
    before = signals.count
    return get_format(options.format).write_run(result, options, out, lambda: signals.count > before)


def summary(spec, result, wall, written):
    """A one-screen account of a run; after a resume, of this part (the last session) and of
    the whole run (``Result.stats``, :mod:`rodmol.output.run_record`) separately."""
    st, t = result.stats, result.t
    t_done = float(t[-1]) if len(t) else 0.0
    state = "done" if result.success else f"STOPPED: {result.message}"
    sessions = st.get("sessions") or []
    lines = [f"rodmol: {spec.name}: {state}" + (f" (resumed at t = {st['resumed_at']:g} s)" if sessions else ""),
             f"  simulated   {t_done:g} of {spec.t_end:g} s, {len(t)} output frames "
             f"(N = {spec.model.n_elements}, backend {st.get('backend', '?')})",
             f"  solver      {st.get('steps', 0)} steps, {st.get('rhs_evals', 0)} RHS evaluations, "
             f"{st.get('jac_evals', 0)} Jacobian evaluations" + (" (whole run)" if sessions else "")]
    part = sessions[-1] if sessions else st  # the work of this process's run
    span = t_done - (part["t_start"] if sessions else float(t[0]) if len(t) else 0.0)
    solver_wall = part.get("wall_time_s", wall)
    stages = "".join(f", {part[key]:.2f} s {what}" for key, what in
                     (("prepare_s", "preparing kernels"), ("equilibrium_s", "equilibrium"))
                     if part.get(key, 0.0) >= 0.005)
    label = "this part " if sessions else "wall time "
    lines.append(f"  {label}  {wall:.2f} s run ({solver_wall:.2f} s integrating"
                 + (f" {part['t_start']:g} to {t_done:g} s in {part.get('steps', 0)} steps" if sessions else "")
                 + f", {_speed(span, solver_wall)} x real time{stages}) + {written.get('seconds', 0.0):.2f} s writing")
    if sessions:
        whole = st.get("wall_time_s", 0.0)
        lines.append(f"  whole run   {whole:.2f} s integrating {t_done - float(t[0]):g} s of simulated time in "
                     f"{len(sessions)} sessions, {_speed(t_done - float(t[0]), whole)} x real time")
    if len(t):
        tip = result.tip[-1]
        lines.append(f"  tip         ({tip[0]:.4f}, {tip[1]:.4f}, {tip[2]:.4f}) m, global, "
                     f"at t = {t_done:g} s")
    if "result" in written:
        lines.append(f"  result      {written['result']}")
    if written.get("views"):
        others = ", ".join(v.name for v in written["views"][1:])
        lines.append(f"  ParaView    {written['views'][0]}" + (f" (+ {others})" if others else "")
                     + f", {written['frames']} frame" + ("" if written["frames"] == 1 else "s")
                     + " (open it by its absolute path)")
    if "pvd" in written:
        others = ", ".join(f"{p}.pvd" for p in written["parts"][1:])
        partial = "" if written["frames"] == written["all_frames"] else f" of {written['all_frames']}"
        lines.append(f"  ParaView    {written['pvd']}" + (f" (+ {others})" if others else "")
                     + f", {written['frames']}{partial} frame" + ("" if written["all_frames"] == 1 else "s"))
    if "result" in written:
        folder = written["result"].parent
        lines.append(f"  next        rodmol render {folder}   |   rodmol plot {folder}")
    return "\n".join(lines)


# --------------------------------------------------------------------------- render, plot

def _speed(simulated, wall):
    """Simulated time per wall time, for the summaries."""
    return f"{simulated / wall:.3g}" if wall > 0 else "inf"


def _result_in(directory):
    """The result in a run directory (result.h5, else result.npz), or in the file given."""
    from ..output.formats import load_result, result_file

    if not Path(directory).exists():
        raise ParameterError(f"no such run directory or result file: {str(directory)!r}")
    try:
        path = result_file(directory)
    except FileNotFoundError as exc:
        raise ParameterError(f"{exc}; run `rodmol run ... --out DIR` first") from None
    try:
        return load_result(path)
    except ParameterError:  # names the file and what is wrong with it
        raise
    except (OSError, KeyError, ValueError) as exc:
        raise ParameterError(f"cannot read {str(path)!r} (another rodmol version?): {exc}") from None


def _folder(directory):
    """Where the pictures of ``directory`` (a run directory, or its result file) go."""
    return directory if directory.is_dir() or not directory.exists() else directory.parent


def _claim(args, names):
    """Refuse the pictures ``names`` drawn earlier, before the result is read, unless ``--overwrite``."""
    from .._files import claim

    claim([_folder(args.directory) / name for name in names], args.overwrite, "`--overwrite`")


def _render(args):
    try:
        size = tuple(int(x) for x in args.size.lower().split("x"))
        if len(size) != 2 or min(size) < 16:
            raise ValueError
    except ValueError:
        raise ParameterError(f"`--size` must be WxH in pixels, e.g. 960x720, got {args.size!r}") from None
    if args.frames < 0:
        raise ParameterError(f"`--frames` must be >= 0, got {args.frames!r}")
    from ..output.pictures import render
    from ..output.run_files import RENDERED

    _claim(args, RENDERED)
    result = _result_in(args.directory)
    for path in render(result, _folder(args.directory), size, args.frames, Progress(stream=sys.stdout),
                       overwrite=args.overwrite):
        print(f"rodmol: wrote {path}")
    return 0


def _plot(args):
    from ..output.pictures import plot
    from ..output.run_files import PLOTTED

    _claim(args, PLOTTED)
    for path in plot(_result_in(args.directory), _folder(args.directory), overwrite=args.overwrite):
        print(f"rodmol: wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
