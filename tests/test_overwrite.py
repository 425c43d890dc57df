"""Nothing written under a name the user gave is replaced without being asked.

One table, :data:`WRITERS`, lists every public function, class and command
of rodmol that writes files. For each: it writes an output; asked to write
again there without ``overwrite`` it refuses with a ParameterError naming
the place and the way to replace it (``overwrite=True``, on the command line
``--overwrite``), before any work and leaving every byte as it was; with
``overwrite=True`` it replaces the output so that the place holds exactly
what a first write of the new output holds (nothing of the old left beside it).
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol import calibrate
from rodmol.calibrate.paper_errors import ErrorTable
from rodmol.calibrate.study import Study
from rodmol.calibrate.sweep import Sweep
from rodmol.cli import commands as cli
from rodmol.output import pictures
from rodmol.output.stream import RunWriter, write_xdmf
from rodmol.output.system_stream import SystemRunWriter, write_system
from rodmol.output.writers import SeriesWriter, write_vtp

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ARM = EXAMPLES / "uniform_arm_air.toml"
RUN = ["--n-elements", "4", "--t-end", "0.02", "--quiet"]
PY, CLI = "overwrite=True", "`--overwrite`"


def model():
    return rodmol.load_scenario(ARM).model.replace(n_elements=4)


def system(names):
    """A System of rods ``names`` clamped to a free body (the names make their folders)."""
    material = rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)
    rod = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=material), 4)
    head = rodmol.RigidBody(mass=0.3, inertia=(2e-4, 3e-4, 4e-4), volume=2.5e-4)
    joints = [rodmol.Joint(("head", (0.03 * i, 0.0, 0.0)), (name, "base")) for i, name in enumerate(names)]
    return rodmol.System(rods={name: rod for name in names}, bodies={"head": head}, joints=joints,
                         medium="water", gravity=(0.0, 0.0, -9.81))


@pytest.fixture(scope="module")
def runs():
    """Results that differ by variant (0, 1): a rod's (fewer frames in 1), a system's (other rods)."""
    rod = rodmol.simulate(model(), 0.05, output_dt=0.01)
    systems = [rodmol.simulate(system(names), 0.02, output_dt=0.01) for names in (["a", "b"], ["c"])]
    return {"rod": [rod, rod.select(slice(0, 3))], "system": systems}


def tracks(variant):
    t = np.linspace(0.0, 0.04, 5 - 2 * variant)
    return calibrate.MarkerTracks(t, np.zeros((len(t), 1, 3)) + variant, ("L",))


def error_tables(variant):
    t = np.linspace(0.0, 1.0, 4 + variant)
    return [ErrorTable(t, 0.01 * t, 0.02 * t, t > 0.5, "full model")]


def command(*argv):
    """Run ``rodmol ARGV`` in this process: a refusal (exit 2) raised as the ParameterError it printed."""
    code = cli.main([str(a) for a in argv])
    if code == 2:
        raise rodmol.ParameterError("the command printed its error")
    assert code == 0


@dataclass
class Writer:
    """``write(place, overwrite, variant, runs)`` writes variant 0 or 1 (other outputs) at ``place``
    (``name`` in the folder of the test, or the folder itself); ``hint``: how to replace it."""

    write: object
    name: str = ""
    hint: str = PY


def _simulator(place, overwrite, variant, runs):
    with rodmol.Simulator(model(), out=place, overwrite=overwrite) as sim:
        for _ in range(2 - variant):
            sim.step(0.01)


def _env(place, overwrite, variant, runs):
    envs = pytest.importorskip("rodmol.control.envs")
    env = envs.ReachEnv(n_elements=4, episode_steps=2, record=place, overwrite=overwrite)
    for _ in range(2 - variant):
        env.reset(seed=0)
        env.step(np.zeros(env.action_space.shape, np.float32))
    env.sim.close()


def _crawl(place, overwrite, variant, runs):
    crawl = pytest.importorskip("rodmol.control.crawl")
    env = crawl.OctopusCrawlEnv(n_elements=3, settle=0.05, episode_steps=2, record=place, overwrite=overwrite)
    for _ in range(2 - variant):
        env.reset(seed=0)
        env.step(np.zeros(env.action_space.shape, np.float32))
    env.close()


def _small_spec():
    from rodmol.calibrate import apply

    return apply(rodmol.load_scenario(ARM), {"discretization.n_elements": 4, "solver.t_end": 0.02})


def _measured(place):
    path = Path(place).parent / "markers.csv"
    if not path.exists():
        result = _small_spec().simulate()
        calibrate.write_marker_tracks(path, calibrate.MarkerTracks(result.t, result.markers,
                                                                   [m.name for m in model().markers]))
    return path


WRITERS = {
    "write_series (xdmf)": Writer(lambda p, o, v, r: rodmol.write_series(r["rod"][v], p, overwrite=o)),
    "write_series (vtp)": Writer(lambda p, o, v, r: rodmol.write_series(r["rod"][v], p, format="vtp",
                                                                        overwrite=o)),
    "write_series (xdmf, then vtp)": Writer(lambda p, o, v, r: rodmol.write_series(
        r["rod"][0], p, format=("xdmf", "vtp")[v], overwrite=o)),
    "write_series (a system's)": Writer(lambda p, o, v, r: rodmol.write_series(r["system"][v], p, overwrite=o)),
    "write_series (a system's, then a rod's)": Writer(lambda p, o, v, r: rodmol.write_series(
        (r["system"][0], r["rod"][0])[v], p, overwrite=o)),
    "output.stream.write_xdmf": Writer(lambda p, o, v, r: write_xdmf(r["rod"][v], p, overwrite=o)),
    "output.writers.write_vtp": Writer(lambda p, o, v, r: write_vtp(r["rod"][v], p, overwrite=o)),
    "output.system_stream.write_system": Writer(lambda p, o, v, r: write_system(r["system"][v], p, overwrite=o)),
    "RunWriter": Writer(lambda p, o, v, r: RunWriter(p, overwrite=o).write_result(r["rod"][v])),
    "SystemRunWriter": Writer(lambda p, o, v, r: SystemRunWriter(p, overwrite=o).write_result(r["system"][v])),
    "SeriesWriter": Writer(lambda p, o, v, r: _series(p, o, v, r)),
    "Result.save": Writer(lambda p, o, v, r: r["rod"][v].save(p, overwrite=o), "result.npz"),
    "simulate(out=)": Writer(lambda p, o, v, r: rodmol.simulate(model(), 0.02 * (2 - v), out=p, overwrite=o)),
    "simulate(system, out=)": Writer(lambda p, o, v, r: rodmol.simulate(system([["a", "b"], ["c"]][v]), 0.02,
                                                                        out=p, overwrite=o)),
    "Simulator(out=)": Writer(_simulator),
    "ReachEnv(record=)": Writer(_env),
    "OctopusCrawlEnv(record=)": Writer(_crawl),
    "output.pictures.render": Writer(lambda p, o, v, r: pictures.render(r["rod"][0], p, size=(64, 48),
                                                                        frames=2 - 2 * v, overwrite=o)),
    "output.pictures.plot": Writer(lambda p, o, v, r: pictures.plot(r["rod"][v], p, overwrite=o)),
    "calibrate.plot_errors": Writer(lambda p, o, v, r: calibrate.plot_errors(error_tables(v), p, overwrite=o),
                                    "errors.png"),
    "calibrate Study.plot": Writer(lambda p, o, v, r: Study({"full model": error_tables(v)[0]}, {}).plot(
        p, overwrite=o), "study.png"),
    "calibrate Sweep.write": Writer(lambda p, o, v, r: Sweep(calibrate.sweep(
        _small_spec(), [{}], client="serial").runs * (2 - v)).write(p, overwrite=o)),
    "calibrate.sweep(out=)": Writer(lambda p, o, v, r: calibrate.sweep(
        _small_spec(), [{"solver.t_end": 0.01}, {"solver.t_end": 0.02}][:2 - v], client="serial", out=p,
        overwrite=o)),
    "calibrate.write_tension_log": Writer(lambda p, o, v, r: calibrate.write_tension_log(
        p, rodmol.calibrate.TensionLog(np.arange(3.0 - v), np.ones((3 - v, 1)), ("c",)), overwrite=o), "log.csv"),
    "calibrate.write_marker_tracks": Writer(lambda p, o, v, r: calibrate.write_marker_tracks(p, tracks(v),
                                                                                             overwrite=o), "m.csv"),
    "calibrate.write_pixel_tracks": Writer(lambda p, o, v, r: calibrate.write_pixel_tracks(
        p, calibrate.PixelTracks(tracks(v).t, tracks(v).xyz[..., :2], ("L",)), overwrite=o), "p.csv"),
    "calibrate.write_control_points": Writer(lambda p, o, v, r: calibrate.write_control_points(
        p, np.zeros((6 - v, 3)), np.zeros((6 - v, 2)), overwrite=o), "c.csv"),
    "rodmol run": Writer(lambda p, o, v, r: command("run", ARM, *RUN, "--out", p, "--chunk-frames", 1 + v,
                                                    *["--overwrite"] * o), hint=CLI),
    "rodmol run --format vtp": Writer(lambda p, o, v, r: command(
        "run", ARM, *RUN[:2], "--t-end", 0.02 * (2 - v), "--quiet", "--format", "vtp", "--out", p,
        *["--overwrite"] * o), hint=CLI),
    "rodmol run (a system)": Writer(lambda p, o, v, r: command(
        "run", EXAMPLES / "two_arms.toml", "--t-end", 0.05 * (2 - v), "--quiet", "--chunk-frames", 1,
        "--out", p, *["--overwrite"] * o), hint=CLI),
    "rodmol render": Writer(lambda p, o, v, r: _picture("render", p, o, v, r, "--size", "64x48", "--frames",
                                                        2 - 2 * v), hint=CLI),
    "rodmol plot": Writer(lambda p, o, v, r: _picture("plot", p, o, v, r), hint=CLI),
    "rodmol sweep": Writer(lambda p, o, v, r: command(
        "sweep", ARM, *RUN, "--serial", "--set", "solver.rtol=" + ",".join(["1e-5", "1e-6"][:2 - v]),
        "--out", p, *["--overwrite"] * o), hint=CLI),
    "rodmol study": Writer(lambda p, o, v, r: command(
        "study", ARM, *RUN[:-1], "--serial", "--measured", _measured(p), "--out", p, *["--overwrite"] * o),
        hint=CLI),
    "rodmol identify": Writer(lambda p, o, v, r: command(
        "identify", ARM, *RUN[:-1], "--serial", "--measured", _measured(p), "--fit", "material.E=50e3:300e3",
        "--out", p, *["--overwrite"] * o), hint=CLI),
}


def _series(place, overwrite, variant, runs):
    result = runs["rod"][variant]
    with SeriesWriter.for_result(result, place, overwrite=overwrite) as writer:
        for k in range(len(result.t)):
            writer.write(result, k)


def _picture(name, place, overwrite, variant, runs, *options):
    if not (Path(place) / "result.h5").exists():
        rodmol.write_series(runs["rod"][0], place)
    command(name, place, *options, *["--overwrite"] * overwrite)


def snapshot(folder):
    """Each file in ``folder``: its bytes and when it was last written [ns]."""
    return {p.relative_to(folder).as_posix(): (p.read_bytes(), p.stat().st_mtime_ns)
            for p in sorted(Path(folder).rglob("*")) if p.is_file()}


@pytest.mark.parametrize("name", list(WRITERS))
def test_every_writer_keeps_an_output_unless_asked_and_then_replaces_it_whole(name, runs, tmp_path, capsys):
    writer = WRITERS[name]
    old, fresh = tmp_path / "old", tmp_path / "fresh"
    if writer.name:  # a file's writer: its folder is there
        old.mkdir(), fresh.mkdir()
    place = old / writer.name if writer.name else old
    writer.write(place, False, 0, runs)
    before = snapshot(old)
    assert before, "wrote nothing"
    with pytest.raises(rodmol.ParameterError) as refused:
        writer.write(place, False, 1, runs)
    message = str(refused.value) if writer.hint == PY else capsys.readouterr().err
    assert str(old) in message and writer.hint in message, message
    assert snapshot(old) == before, "changed although refused"
    writer.write(place, True, 1, runs)
    writer.write(fresh / writer.name if writer.name else fresh, False, 1, runs)
    replaced = snapshot(old)
    assert sorted(replaced) == sorted(snapshot(fresh)), "not what a first write of the new output holds"
    assert replaced != before, "not replaced"
