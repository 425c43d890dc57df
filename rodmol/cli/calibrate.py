"""The command line's calibration commands (registered by :mod:`rodmol.cli.commands`):

    rodmol study    SCENARIO.toml --measured MARKERS.csv [--tensions LOG.csv] [--out DIR]
    rodmol identify SCENARIO.toml --measured MARKERS.csv --fit material.E=50e3:300e3 ... [--out DIR]
    rodmol sweep    SCENARIO.toml --set material.E=80e3,110e3 --set medium.Cy,Cz=2,3 --out DIR
    rodmol sweep    SCENARIO.toml --runs RUNS.csv --out DIR   # one run per row, dotted keys in the header
    rodmol identify SYSTEM.toml --measured arm1=MARKERS.csv --tensions arm1=LOG.csv \
                    --fit rods.arm1.material.E=50e3:300e3 --fit bodies.head.mass=0.1:1

A system's file names the part a measurement sees (``--measured PART=CSV``:
a rod's markers, ``<rod>.tip`` or a body; repeat for several parts of one
recording) and the rod a tension log drives (``--tensions ROD=CSV``, repeat).

Every command takes ``--example NAME`` instead of a file, the run options of
``rodmol run`` and ``--workers N`` (a LocalCluster of N processes, default
one per core), ``--scheduler ADDRESS`` (a running dask cluster) or
``--serial``. Outputs already in ``--out`` are kept unless ``--overwrite``
(refused before any run). See ``docs/calibration.md``.
"""

import csv
import json
import sys
from pathlib import Path

from ..errors import ParameterError

#: How the command line asks to replace earlier outputs.
OVERWRITE = "`--overwrite`"


def add_commands(commands):
    """Add ``study``, ``identify`` and ``sweep`` to the ``rodmol`` subparsers."""
    study = commands.add_parser("study", help="the paper's worsened-model study (Table V) against measured markers")
    _common(study, measured=True)
    study.set_defaults(command=_study)

    fit = commands.add_parser("identify", help="fit parameters to measured markers (bounded least squares)")
    _common(fit, measured=True)
    fit.add_argument("--fit", action="append", default=[], metavar="KEY=LOW:HIGH", required=True,
                     help="a parameter to fit and its bounds, e.g. material.E=50e3:300e3 (repeat)")
    fit.add_argument("--start", action="append", default=[], metavar="KEY=VALUE",
                     help="a starting value (default: the scenario's)")
    fit.set_defaults(command=_identify)

    batch = commands.add_parser("sweep", help="run a scenario over a grid or a list of dotted overrides")
    _common(batch, measured=False)
    batch.add_argument("--set", action="append", default=[], metavar="KEY=V1,V2,...",
                       help="a grid axis: a dotted key and its values (repeat: every combination)")
    batch.add_argument("--runs", type=Path, metavar="CSV", help="one run per row; dotted keys in the header")
    batch.add_argument("--measured", action="append", metavar="[PART=]CSV",
                       help="add eq. (15) averages to the summary (a system's: PART=CSV, repeat)")
    batch.set_defaults(command=_sweep)


def _common(parser, measured):
    from .options import EXAMPLES, add_run_options

    parser.add_argument("scenario", nargs="?", help="TOML scenario file")
    parser.add_argument("--example", choices=EXAMPLES, metavar="NAME", help="one of the paper's tests instead")
    if measured:
        parser.add_argument("--measured", action="append", required=True, metavar="[PART=]CSV",
                            help="measured marker tracks: t, then x, y, z of each marker [s, m]; a system's "
                                 "name the part they see: PART=CSV (a rod, ROD.tip or a body; repeat)")
    parser.add_argument("--tensions", action="append", metavar="[ROD=]CSV",
                        help="drive the cables by a tension log (t, one column per cable) [s, N]; a "
                             "system's name the rod: ROD=CSV (repeat)")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N", help="LocalCluster worker processes (default: cores)")
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running dask scheduler, e.g. tcp://host:8786")
    where.add_argument("--serial", action="store_true", help="run in this process, without dask")
    add_run_options(parser)


def _setup(args):
    """(spec, client, say) from the common options."""
    from ..calibrate import read_tension_log
    from ..calibrate.parallel import SERIAL
    from ..calibrate.variants import apply
    from .options import load_spec

    spec = load_spec(args)
    for rod, path in _named(spec, args.tensions, "--tensions", "ROD").items():
        spec = apply(spec, read_tension_log(path, clip_negative=True).overrides(rod))
    if args.workers is not None and args.workers < 1:
        raise ParameterError(f"`--workers` must be >= 1, got {args.workers}")
    client = SERIAL if args.serial else args.scheduler
    say = (lambda *a, **k: None) if args.quiet else print
    return spec, client, say


def _named(spec, texts, option, what):
    """{name or None: Path} of the ``option``'s ``texts``: one plain CSV for a
    single rod, ``NAME=CSV`` each for a system (``what``: what NAME is)."""
    from ..systems import System

    texts = list(texts or [])
    if not isinstance(spec.model, System):
        if len(texts) > 1:
            raise ParameterError(f"`{option}` is given {len(texts)} times: a single rod's scenario takes one")
        return {None: Path(texts[0])} if texts else {}
    named = {}
    for text in texts:
        name, sep, path = text.partition("=")
        if not sep or not name.strip() or not path.strip():
            raise ParameterError(f"`{option}` of a system takes {what}=CSV (e.g. {option} "
                                 f"{next(iter(spec.model.given_rods))}=file.csv), got {text!r}")
        if name.strip() in named:
            raise ParameterError(f"`{option}` names {name.strip()!r} twice")
        named[name.strip()] = Path(path.strip())
    return named


def _measured(spec, texts):
    """The ``--measured`` tracks: a CSV path (a single rod), {part: CSV path} (a system) or None."""
    named = _named(spec, texts, "--measured", "PART")
    if not named:
        return None
    return named.get(None, named)


def _progress(args, label):
    from ..calibrate.parallel import ProgressLine

    return None if args.quiet else ProgressLine(label)


#: The files ``rodmol study`` and ``rodmol identify`` write in ``--out``.
STUDY, IDENTIFY = ("study.md", "errors.png"), ("fit.md", "fit.json", "errors.png")


def _out(args, spec, kind, names=()):
    """The output directory (made), its files ``names`` refused before any run unless
    ``--overwrite`` (then removed: :func:`rodmol._files.claim`)."""
    from .._files import claim, output_directory

    out = output_directory(args.out or Path("out") / f"{spec.name}-{kind}", "--out")
    claim([out / name for name in names], args.overwrite, OVERWRITE)
    return out


def _study(args):
    from ..calibrate import worsened_models

    spec, client, say = _setup(args)
    out = _out(args, spec, "study", STUDY)
    study = worsened_models(spec, _measured(spec, args.measured), client=client, n_workers=args.workers,
                            progress=_progress(args, "rodmol study"))
    (out / "study.md").write_text(study.table() + "\n", encoding="utf-8")
    study.plot(out / "errors.png", f"{spec.name}: errors of eq. (15)", overwrite=args.overwrite)
    say(study.table())
    say(f"rodmol: wrote {out / 'study.md'} and {out / 'errors.png'}")
    return 0


def _identify(args):
    from ..calibrate import identify, plot_errors

    spec, client, say = _setup(args)
    bounds = {}
    for text in args.fit:
        key, values = _split(text, "--fit")
        low, _, high = values.partition(":")
        bounds[key] = (_value(low, "--fit"), _value(high, "--fit"))
    start = {key: _value(v, "--start") for key, v in (_split(t, "--start") for t in args.start)}
    out = _out(args, spec, "identify", IDENTIFY)
    fit = identify(spec, _measured(spec, args.measured), bounds, start=start, client=client, n_workers=args.workers,
                   progress=None if args.quiet else lambda i, cost: print(f"rodmol identify: iteration {i}, "
                                                                           f"cost {cost:.6g}", file=sys.stderr))
    (out / "fit.md").write_text(fit.table() + "\n", encoding="utf-8")
    (out / "fit.json").write_text(json.dumps(dict(
        parameters=fit.names, value=fit.value.tolist(), sigma=fit.sigma.tolist(), start=fit.start.tolist(),
        residual_m=fit.residual, runs=fit.runs, success=fit.success, message=fit.message,
        mean_error=[fit.errors_before.mean_average, fit.errors_after.mean_average],
        tip_error=[fit.errors_before.tip_average, fit.errors_after.tip_average]), indent=2), encoding="utf-8")
    plot_errors([fit.errors_before, fit.errors_after], out / "errors.png",
                f"{spec.name}: before and after the fit", overwrite=args.overwrite)
    say(fit.table())
    say(f"rodmol: wrote {out / 'fit.md'}, {out / 'fit.json'} and {out / 'errors.png'}")
    return 0 if fit.success else 1


def _sweep(args):
    from ..calibrate import grid, sweep

    spec, client, say = _setup(args)
    if bool(args.set) == bool(args.runs):
        raise ParameterError("give the runs as `--set KEY=V1,V2,...` (a grid) or `--runs FILE.csv`, not both")
    if args.set:
        axes = {}
        for text in args.set:
            key, values = _split(text, "--set")
            axes[key] = [_value(v, "--set") for v in values.split(",")]
        overrides = grid(axes)
    else:
        overrides = _read_runs(args.runs)
    from ..calibrate.sweep import claim_outputs

    out = _out(args, spec, "sweep")
    claim_outputs(out, args.overwrite, OVERWRITE)
    runs = sweep(spec, overrides, client=client, out=out, measured=_measured(spec, args.measured),
                 n_workers=args.workers, progress=_progress(args, "rodmol sweep"), overwrite=args.overwrite)
    say(runs.table())
    say(f"rodmol: wrote {len(runs.runs)} results and {out / 'summary.csv'}")
    return 0 if all(r.success for r in runs.runs) else 1


def _split(text, option):
    key, sep, value = text.partition("=")
    if not sep or not key or not value:
        raise ParameterError(f"`{option}` takes KEY=VALUE (e.g. material.E=110e3), got {text!r}")
    return key.strip(), value.strip()


def _value(text, option):
    """A command-line value: true/false, a number, or the text itself."""
    text = text.strip()
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    if not text:
        raise ParameterError(f"`{option}`: missing value")
    return text


def _read_runs(path):
    """Overrides from a CSV: a header of dotted keys (quote a comma-joined key),
    one run per row; errors name the line."""
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            rows = [(n, r) for n, r in enumerate(csv.reader(handle), start=1)
                    if any(c.strip() for c in r) and not r[0].strip().startswith("#")]
    except OSError as exc:
        raise ParameterError(f"cannot read the runs table {str(path)!r}: {exc.strerror}") from None
    if len(rows) < 2:
        raise ParameterError(f"{path}: needs a header of dotted keys and at least one run")
    header = [c.strip() for c in rows[0][1]]
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise ParameterError(f"{path}:{line}: {len(row)} values for the {len(header)} keys of the header")
    return [{k: _value(v, f"{path}:{line}") for k, v in zip(header, row)} for line, row in rows[1:]]
