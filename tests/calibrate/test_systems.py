"""Calibration of a System: dotted keys of its rods and bodies, measurements of
a named part, identification, sweeps, the study and the command line."""

import json
import time
from pathlib import Path

import numpy as np
import pytest

import rodmol
from rodmol import ParameterError, load_result
from rodmol.calibrate import MarkerTracks, apply, grid, identify, sweep, worsened_models, write_marker_tracks
from rodmol.calibrate.synthetic import synthesize
from rodmol.calibrate.variants import current
from rodmol.cli.commands import main
from rodmol.scenario.file import parse_scenario

TWO_ARMS = Path(__file__).resolve().parents[2] / "examples" / "two_arms.toml"
#: Two markers on the right arm (a rod's table ends where the next [[rod]] starts).
MARKERS = '[[rod.marker]]\ns = 0.1\nname = "mid"\n[[rod.marker]]\ns = 0.2\nname = "end"\n\n'


def two_arms_text(marked=True, **replace):
    """examples/two_arms.toml (N = 8 and 10, 0.5 s), with markers on the right arm
    and each ``old=new`` text of ``replace`` replaced once."""
    text = TWO_ARMS.read_text()
    if marked:
        first = text.index("[[rod]]")
        second = text.index("[[rod]]", first + 1)
        text = text[:second] + MARKERS + text[second:]
    for old, new in replace.values():
        assert text.count(old) >= 1
        text = text.replace(old, new, 1)
    return text


def two_arms(**replace):
    return parse_scenario(two_arms_text(**replace), source="two_arms.toml")


def test_system_keys_reach_the_named_part_and_leave_the_rest():
    spec = two_arms()
    new = apply(spec, {"rods.right.material.E": 2e5, "bodies.head.mass": 0.4, "bodies.head.drag.0,1,2": 0.7,
                       "bodies.head.inertia.2": 3e-4, "medium.Cy,Cz": 3.0, "material.mu": 0.0,
                       "rods.left.tension.1.scale": 2.0, "solver.t_end": 0.3})
    right, left, head = new.model.rods["right"], new.model.rods["left"], new.model.bodies["head"]
    assert right.rod.material.E == 2e5 and left.rod.material.E == 1e5
    assert right.rod.material.mu == left.rod.material.mu == 0.0  # a rod's key without a rod: every rod
    assert head.mass == 0.4 and np.allclose(head.drag, [0.7, 0.7, 0.7, 1e-3, 1e-3, 1e-3])
    assert np.allclose(np.diag(head.inertia), [2e-4, 2e-4, 3e-4])
    assert right.medium.Cy == left.medium.Cz == new.model.medium.Cy == 3.0
    assert left.tensions(1.0)[0] == pytest.approx(0.6) and right.tensions(1.0)[0] == pytest.approx(0.3)
    assert new.t_end == 0.3 and [m.name for m in right.markers] == ["mid", "end"]
    assert new.model.clamps["right"][0] == "head" and new.model.base_motion("left").position == \
        spec.model.base_motion("left").position
    assert spec.model.bodies["head"].mass == 0.3  # the original is untouched
    assert current(new, "rods.right.material.E") == 2e5 and current(new, "bodies.head.drag.1") == 0.7
    assert current(new, "medium.Cy") == 3.0 and current(new, "rods.left.tension.1.scale") == 2.0
    assert current(new, "material.mu") == 0.0


@pytest.mark.parametrize("overrides, message", [
    ({"rods.rigth.material.E": 1e5}, r"'rods.rigth.material.E': the system has no rod named 'rigth'; "
                                     r"did you mean 'right'\? \(rods: right, left\)"),
    ({"rods.right.material.EE": 1e5}, r"unknown override 'rods.right.material.EE' \(rod 'right'\); did you "
                                      r"mean 'rods.right.material.E'\?; valid keys: rods.right.material.E, "),
    ({"bodies.head.mas": 0.4}, r"unknown override 'bodies.head.mas' \(body 'head'\); did you mean "
                               r"'bodies.head.mass'\?; valid keys: bodies.head.mass, bodies.head.volume, "
                               r"bodies.head.inertia\[.<i>\]"),
    ({"bodies.hed.mass": 0.4}, r"no body named 'hed'; did you mean 'head'\?"),
    ({"bodies.head.drag.6": 1.0}, r"'bodies.head.drag.6': `drag` of body 'head' has components 0 to 5"),
    ({"rods.right.medium.Cy": 1.0}, r"the medium is the system's, around every rod and body: use 'medium.Cy'"),
    ({"tension.1": 1.0}, r"'tension.1': name the rod whose cable it is, 'rods.<rod>.tension.1'"),
    ({"materail.E": 1.0}, r"unknown override 'materail.E' for a system; did you mean 'material.E'\?; valid keys:"
                          r"\n  rods.<rod>.<key>, rods right, left, keys material.E"),
    ({"bodies.head.mass": -1.0}, r"override 'bodies.head.mass': `mass` must be > 0 kg, got -1.0"),
    ({"rods.right.material.E": 0.0}, r"override 'rods.right.material.E': `E` must be > 0 Pa, got 0.0"),
    ({"rods.left.tension.7": 1.0}, r"'rods.left.tension.7': no cable named '7'; the cables are \['cable 1'\]"),
])
def test_bad_system_keys_name_the_key_the_part_and_the_valid_ones(overrides, message):
    with pytest.raises(ParameterError, match=message):
        apply(two_arms(), overrides)


def test_a_rod_key_without_a_rod_reads_only_a_common_value():
    spec = apply(two_arms(), {"rods.right.material.E": 3e5})
    with pytest.raises(ParameterError, match=r"the rods' values differ .*: name the rod, e.g. "
                                             r"'rods.right.material.E'"):
        current(spec, "material.E")


def test_single_rod_keys_suggest_a_near_miss():
    spec = rodmol.calibrate.spec_of(rodmol.paper_arm(10), 1.0)
    with pytest.raises(ParameterError, match=r"unknown override 'material.EE'; did you mean 'material.E'\?"):
        apply(spec, {"material.EE": 1.0})


@pytest.mark.parametrize("measured, message", [
    (lambda t: MarkerTracks(t.t, t.xyz, t.names), "must say which part it sees"),
    (lambda t: {"rigth": t}, r"part 'rigth' is no rod or body of the system; did you mean 'right'\?"),
    (lambda t: {"left": t}, "rod 'left' has no markers: measure its tip, part 'left.tip'"),
    (lambda t: {"head": t}, "the measurement of 'head' has 2 markers, body 'head' 1"),
    (lambda t: {"right": t, "head.x": t}, "is no rod or body"),
])
def test_a_measurement_must_name_a_part_of_the_system(measured, message):
    spec = two_arms()
    t = np.linspace(0.0, 0.5, 6)
    tracks = MarkerTracks(t, np.zeros((6, 2, 3)), ("mid", "end"))
    with pytest.raises(ParameterError, match=message):
        identify(spec, measured(tracks), {"rods.right.material.E": (3e4, 5e5)}, client="serial")


def test_identification_recovers_a_rods_modulus_from_its_markers():
    """E of the right arm from the noise-free tracks of its two markers, made with
    E = 120 kPa: from 30% off it lands within 1e-3."""
    spec = two_arms()
    truth = {"rods.right.material.E": 1.2e5}
    measured = synthesize(spec, truth, noise_px=0.0, part="right", rate=50.0).true_markers
    assert measured.part == "right" and measured.names == ("mid", "end") and measured.xyz.shape == (26, 2, 3)
    started = time.perf_counter()
    fit = identify(spec, measured, {"rods.right.material.E": (3e4, 5e5)},
                   start={"rods.right.material.E": 0.7 * 1.2e5}, client="serial")
    wall = time.perf_counter() - started
    assert fit.success, fit.message
    assert abs(fit.values["rods.right.material.E"] / 1.2e5 - 1.0) < 1e-3, fit.table(truth)
    assert fit.errors_before.mean_average > 0.01 and fit.errors_after.mean_average < 1e-4
    assert fit.runs <= 12 and wall < 30.0


def test_identification_recovers_a_bodys_mass_from_two_parts_of_one_recording():
    """The head's mass from the right arm's markers and the head's origin seen
    together (one set of markers: the arm's two, then the head)."""
    spec = two_arms()
    truth = {"bodies.head.mass": 0.4}
    arm = synthesize(spec, truth, noise_px=0.0, part="right", rate=50.0).true_markers
    head = synthesize(spec, truth, noise_px=0.0, part="head", rate=50.0).true_markers
    fit = identify(spec, [arm, head], {"bodies.head.mass": (0.1, 1.0)}, start={"bodies.head.mass": 1.3 * 0.4},
                   client="serial")
    assert fit.success and abs(fit.values["bodies.head.mass"] / 0.4 - 1.0) < 1e-3, fit.table(truth)


def test_sweep_over_a_rods_modulus_and_a_bodys_mass_gives_the_direct_runs(tmp_path):
    """Each sweep point equals a run of the system file written with those
    values; the runs' directories read back; the summary has each part."""
    spec = two_arms()
    overrides = grid({"rods.right.material.E": [8e4, 1.5e5], "bodies.head.mass": [0.3, 0.6]})
    runs = sweep(spec, overrides, client="serial", out=tmp_path, keep=True)
    assert all(r.success for r in runs.runs)
    direct = two_arms(E=("E = 1e5", "E = 1.5e5"), mass=("mass = 0.3", "mass = 0.6")).simulate()
    run = runs.runs[3]
    assert run.overrides == {"rods.right.material.E": 1.5e5, "bodies.head.mass": 0.6}
    for part in ("right", "left"):
        assert np.array_equal(run.result[part].markers, direct[part].markers)
        assert np.array_equal(run.result[part].tip, direct[part].tip)
    assert np.array_equal(run.result["head"].position, direct["head"].position)
    assert run.value["right.tip_x"] == direct["right"].tip[-1, 0]
    assert run.value["head.z"] == direct["head"].position[-1, 2]
    # A heavier head sinks further in the same 0.5 s; a stiffer arm's tip travels less.
    assert runs.runs[1].value["head.travel"] > runs.runs[0].value["head.travel"]
    assert runs.runs[2].value["right.tip_travel"] < runs.runs[0].value["right.tip_travel"]
    saved = load_result(tmp_path / "run_0003")
    assert np.allclose(saved["head"].position, direct["head"].position)
    assert json.loads((tmp_path / "run_0003" / "overrides.json").read_text())["bodies.head.mass"] == "0.6"
    assert np.allclose(runs.result(3)["right"].tip, direct["right"].tip)


def test_sweep_of_a_system_on_a_local_cluster_equals_serial_runs(dask_client):
    spec = two_arms()
    overrides = [{"rods.left.material.E": 7e4}, {"bodies.head.mass": 0.5, "medium.drag": False}]
    runs = sweep(spec, overrides, client=dask_client, keep=True)
    for o, run in zip(overrides, runs.runs):
        serial = apply(spec, o).simulate()
        assert run.success and np.array_equal(run.result["left"].tip, serial["left"].tip)
        assert np.array_equal(run.result["head"].position, serial["head"].position)


def test_study_of_a_system_changes_every_rod():
    spec = two_arms()
    measured = synthesize(spec, noise_px=0.0, part="right.tip", rate=50.0).true_markers
    study = worsened_models(spec, measured, client="serial")
    assert study.errors["full model"].tip_average < 1e-6  # its own run
    assert study.errors["linear elastic"].tip_average > 1e-3
    assert study.outcomes["linear elastic"].success


def test_system_file_from_the_command_line(tmp_path, capsys):
    """sweep, identify and study of a system file: the keys of its parts, the
    measurement of a named part (PART=CSV)."""
    scenario = tmp_path / "two_arms.toml"
    scenario.write_text(two_arms_text())
    code = main(["sweep", str(scenario), "--serial", "--quiet", "--set", "rods.right.material.E=8e4,1.5e5",
                 "--set", "bodies.head.mass=0.3,0.6", "--out", str(tmp_path / "sweep")])
    assert code == 0 and (tmp_path / "sweep" / "summary.md").read_text().count("\n") == 2 + 4
    truth = synthesize(two_arms(), {"rods.right.material.E": 1.2e5}, noise_px=0.0, part="right.tip",
                       rate=50.0).true_markers
    write_marker_tracks(tmp_path / "tip.csv", truth)
    code = main(["identify", str(scenario), "--serial", "--quiet", "--measured", f"right.tip={tmp_path / 'tip.csv'}",
                 "--fit", "rods.right.material.E=3e4:5e5", "--start", "rods.right.material.E=8.4e4",
                 "--out", str(tmp_path / "fit")])
    fit = json.loads((tmp_path / "fit" / "fit.json").read_text())
    assert code == 0 and fit["parameters"] == ["rods.right.material.E"]
    assert abs(fit["value"][0] / 1.2e5 - 1.0) < 1e-3
    code = main(["study", str(scenario), "--serial", "--measured", f"right.tip={tmp_path / 'tip.csv'}",
                 "--out", str(tmp_path / "study")])
    assert code == 0 and "| linear elastic |" in capsys.readouterr().out
    code = main(["identify", str(scenario), "--serial", "--measured", str(tmp_path / "tip.csv"),
                 "--fit", "rods.right.material.E=3e4:5e5", "--out", str(tmp_path / "bad")])
    assert code == 2 and "`--measured` of a system takes PART=CSV" in capsys.readouterr().err


def test_a_system_built_in_python_takes_keys_through_spec_of():
    arm = rodmol.Model(rodmol.Rod(0.2, radius=0.01, material=rodmol.Material(E=1e5, nu=0.5, mu=300.0, rho=1080.0)),
                       6, cables=[rodmol.Cable((0.005, 0.0), 0.2, name="c", tension=[(0.0, 0.0), (0.1, 0.2)])],
                       markers=[rodmol.Marker(0.2, name="tip")])
    head = rodmol.RigidBody(0.2, (1e-4, 1e-4, 1e-4), volume=1e-4)
    system = rodmol.System({"arm": arm}, {"head": head}, [rodmol.Joint(("head", (0.0, 0.0, 0.0)), ("arm", "base"))],
                           medium="water")
    spec = rodmol.calibrate.spec_of(system, 0.2, output_dt=0.05)
    runs = sweep(spec, [{"rods.arm.tension.c.scale": 2.0, "bodies.head.volume": 2e-4}], client="serial", keep=True)
    doubled = arm.replace(cables=[rodmol.Cable((0.005, 0.0), 0.2, name="c", tension=[(0.0, 0.0), (0.1, 0.4)])])
    lighter = rodmol.RigidBody(0.2, (1e-4, 1e-4, 1e-4), volume=2e-4)
    direct = rodmol.simulate(system.replace(rods={"arm": doubled}, bodies={"head": lighter}), 0.2, output_dt=0.05)
    assert runs.runs[0].success
    np.testing.assert_allclose(runs.runs[0].result["arm"].markers, direct["arm"].markers, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(runs.runs[0].result["head"].position, direct["head"].position, rtol=0.0, atol=1e-12)
