"""What the ``rodmol`` commands share: the paper's example names, the run
options and reading the scenario with the command line's overrides."""

from pathlib import Path

from ..errors import ParameterError
from ..output.formats import DEFAULT, FORMATS

#: The paper's tests, for ``--example``.
EXAMPLES = ("bending", "reaching", "fetching")


def add_run_options(parser):
    """The options of a run: output, backend, grid, scheme, end time, budget, format."""
    parser.add_argument("--out", type=Path, metavar="DIR", help="output directory (default: [output] directory, "
                                                 "else out/NAME)")
    parser.add_argument("--backend", metavar="NAME", help="solver backend (cvode, galpha, rk23)")
    parser.add_argument("--n-elements", type=int, metavar="N", help="number of elements N")
    parser.add_argument("--scheme", metavar="NAME", help="spatial scheme (centred, upwind)")
    parser.add_argument("--t-end", type=float, metavar="T", help="end time [s]")
    parser.add_argument("--max-wall-time", type=float, metavar="S",
                        help="wall-time budget [s]: stop the run there (the frames done are kept)")
    parser.add_argument("--format", choices=tuple(FORMATS), help="outputs: " + " or ".join(
        f"{f.summary} ({f.name}{', default' if f.name == DEFAULT else ''})" for f in FORMATS.values()))
    parser.add_argument("--chunk-frames", type=int, metavar="N", help="output frames per chunk file, "
                        "the restart points of --resume (default: [output] chunk_frames, else 2000)")
    parser.add_argument("--resume", action="store_true", help="continue the unfinished run in the output "
                        "directory from its last complete chunk (xdmf format), with the settings it was made "
                        "with; refused if the scenario or the options ask for other ones")
    parser.add_argument("--resume-anyway", action="store_true", help="--resume even if the scenario or the "
                        "options changed a setting (rtol, scheme, backend, the model, ...): the run goes on "
                        "with the new ones (the grid and the output times cannot change)")
    parser.add_argument("--overwrite", action="store_true", help="replace the outputs in the output directory "
                        "(a run, finished or not, with all of its files and pictures; a study's, fit's or "
                        "sweep's files): they are removed first; without it they are kept and the command "
                        "refused before any run")
    parser.add_argument("--quiet", action="store_true", help="print nothing but errors")


def load_spec(args):
    """The checked scenario, with the command line's overrides; raises ScenarioError."""
    from ..scenario.file import Override, load_scenario, parse_scenario

    overrides = {}
    for option, key in (("backend", "solver.backend"), ("n_elements", "discretization.n_elements"),
                        ("scheme", "discretization.scheme"), ("t_end", "solver.t_end"),
                        ("max_wall_time", "solver.max_wall_time")):
        if getattr(args, option) is not None:
            overrides[key] = Override(getattr(args, option), "--" + option.replace("_", "-"))
    if args.example and args.scenario:
        raise ParameterError("give either a scenario file or `--example`, not both")
    if args.example:
        text = f'name = "{args.example}"\narm = "paper"\nscenario = "{args.example}"\n'
        return parse_scenario(text, source=f"<example {args.example}>", overrides=overrides)
    if not args.scenario:
        raise ParameterError("give a scenario file (rodmol run FILE.toml) or `--example NAME`")
    return load_scenario(args.scenario, overrides=overrides)
