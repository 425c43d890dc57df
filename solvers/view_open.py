"""How long ParaView takes to open a streamed view, by the number of frames it
shows: why the views of long runs show at most ``rodmol.output.parts.MAX_SHOWN``
frames by default.

Each case runs ``examples/fetching.toml`` at N = 10 (the XML of a frame does
not depend on N) with ``every=1`` (every output frame in the views), then
times ParaView's ``pvpython`` reading ``rod.xdmf``'s time steps (what File >
Open does before the first picture) and then drawing the last frame. Needs
ParaView (``pvpython`` on the path).

    python solvers/view_open.py [--quick | --smoke] [--out DIR]
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap

import _common as C

SCRIPT = "view_open.py"
FETCHING = os.path.join(os.path.dirname(C.HERE), "examples", "fetching.toml")

OPEN = textwrap.dedent("""
    import json, sys, time
    from paraview.simple import Xdmf3ReaderS
    started = time.perf_counter()
    reader = Xdmf3ReaderS(FileName=[sys.argv[1]])
    reader.UpdatePipelineInformation()
    times = reader.TimestepValues
    opened = time.perf_counter()
    reader.UpdatePipeline(times[-1])
    print(json.dumps(dict(frames=len(times), open_s=opened - started,
                          last_frame_s=time.perf_counter() - opened)))
""")


def write_views(t_end, out):
    from rodmol.output.stream import RunWriter
    from rodmol.scenario.file import Override, load_scenario

    overrides = {"solver.t_end": Override(t_end, "--t-end"),
                 "discretization.n_elements": Override(10, "--n-elements")}
    load_scenario(FETCHING, overrides=overrides).simulate(out=RunWriter(out, every=1))
    return os.path.abspath(os.path.join(out, "rod.xdmf"))  # ParaView 5.11 needs the absolute path


def main(argv=None):
    args = C.parse_args(__doc__.splitlines()[0], argv)
    sys.path.insert(0, os.path.dirname(C.HERE))
    header = C.header_lines(args, SCRIPT)
    if shutil.which("pvpython") is None:
        raise SystemExit("view_open.py needs ParaView's pvpython on the path")
    rows = []
    for t_end in C.pick(args, [8.0, 60.0, 600.0], [8.0, 60.0], [0.5]):
        with tempfile.TemporaryDirectory(prefix="rodmol_views_") as tmp:
            script = os.path.join(tmp, "open.py")
            with open(script, "w") as f:
                f.write(OPEN)
            view = write_views(t_end, os.path.join(tmp, "out"))
            done = subprocess.run(["pvpython", script, view], capture_output=True, text=True, timeout=3600)
            if done.returncode != 0:
                raise RuntimeError(done.stderr[-3000:])
            row = dict(t_end_s=t_end, **json.loads(done.stdout.strip().splitlines()[-1]))
        row["open_ms_per_1000_frames"] = 1e6 * row["open_s"] / row["frames"]
        rows.append(row)
        print(f"{row['frames']} frames: opened in {row['open_s']:.2f} s, last frame in "
              f"{row['last_frame_s']:.2f} s", flush=True)
    C.write_results(args, "view_open", "ParaView opening a streamed view (rod.xdmf)", header, rows,
                    [("Open and last-frame times by frames shown", C.markdown_table(rows))])


if __name__ == "__main__":
    main()
