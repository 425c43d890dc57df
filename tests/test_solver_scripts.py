"""The solver studies under solvers/ run end to end (tiny --smoke sizes),
write their CSV, Markdown and PNG outputs, and each produces the figure it
exists for within a loose physical bound: an observed order, an error against
its reference, an agreement or a ratio measured in the same run. Wall times
themselves are not checked. core_speed.py also checks out the pre-refactor
commit into a temporary git worktree (skipped outside a git checkout that has it).

The scripts run in this process (``main(argv)``, as their ``__main__`` block
calls it): a fresh interpreter per script would add its start and the loading
of the compiled kernels, a second or two each, to runs of about as long. One
script runs as a command (``python solvers/<script> --smoke``), for the part
they all share: the command line's start, ``_common``'s set-up and the exit code.
Scripts that start workers of their own (old and new trees side by side) are
marked ``subprocess``."""

import csv
import importlib
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rows(path):
    """The rows of one of the scripts' CSV tables (the '#' header lines skipped), values as floats where they parse."""
    with open(path) as f:
        table = list(csv.DictReader(line for line in f if not line.startswith("#")))
    assert table, f"{path.name} holds no rows"
    return [{key: _number(value) for key, value in row.items()} for row in table]


def _number(text):
    try:
        return float(text)
    except ValueError:
        return {"True": True, "False": False}.get(text, text)


def _scaling(out):
    by_n = {}
    for row in rows(out / "scaling.csv"):
        by_n.setdefault(row["N"], []).append(row)
    for n, runs in by_n.items():
        steps = [row["steps"] for row in runs]
        # the same problem at the same tolerance: the linear solvers change the steps, not their number's scale
        assert max(steps) < 2.5 * min(steps), (n, steps)
        assert all(row["h_min_s"] <= row["h_median_s"] <= row["h_max_s"] for row in runs)
    long = rows(out / "scaling_long.csv")
    assert all(row["success"] and row["max_quaternion_drift"] < 1e-3 for row in long)


def _temporal(out):
    sweep = sorted(rows(out / "temporal.csv"), key=lambda row: row["rtol"])
    for row in sweep:  # the tip error follows the tolerance (relative to L, against rtol 1e-10)
        assert row["tip_err_max"] < 10 * row["rtol"], row
    assert sweep[0]["tip_err_max"] < sweep[-1]["tip_err_max"]
    cvode, rk23 = rows(out / "temporal_rk23.csv")
    assert cvode["tip_err_max"] < 1e-6 and rk23["tip_err_max"] < 1e-6


def _work_precision(out):
    table = rows(out / "work_precision.csv")
    assert all(row["success"] for row in table)
    for row in table:  # every backend and linear solver meets its tolerance against the reference
        assert row["tip_err_max"] < 10 * row["rtol"], row


def _convergence(out):
    for row in rows(out / "convergence.csv"):
        if not math.isnan(row["equilibrium_order"]):
            nominal = 2.0 if row["scheme"] == "centred" else 1.0
            assert abs(row["equilibrium_order"] - nominal) < 0.25, row


def _release(out):
    for row in rows(out / "release.csv"):
        # released in water, the explicit solver is limited by the axial waves, the implicit one is not
        assert row["cvode_speedup_over_rk23"] > 1, row


def _profile_rhs(out):
    calls = {row["operation"]: row["microseconds"] for row in rows(out / "profile_rhs_calls.csv")}
    kernel = calls["right-hand side, bare kernel"]
    assert kernel <= calls["right-hand side, compiled (SemiDiscrete call)"] * 1.5
    # the Jacobian is a few dozen coloured kernel evaluations, not one per state variable
    assert calls["Jacobian, compiled (34 kernel evaluations)"] < 200 * kernel


def _continuum(out):
    for row in rows(out / "continuum.csv"):
        if not math.isnan(row["tip_order"]):
            low = 1.6 if row["scheme"] == "centred" else 0.8
            assert low < row["tip_order"] < low + 0.8, row


def _schemes(out):
    table = rows(out / "schemes.csv")
    for test in {row["test"] for row in table}:
        for scheme in ("centred", "upwind"):
            errors = [row["tip_err_mm"] for row in sorted(table, key=lambda row: row["N"])
                      if row["test"] == test and row["scheme"] == scheme]
            assert errors[-1] < errors[0], (test, scheme, errors)  # refining reduces the error
        finest = max(row["N"] for row in table if row["test"] == test)
        by_scheme = {row["scheme"]: row["tip_err_mm"] for row in table if row["test"] == test and row["N"] == finest}
        assert by_scheme["centred"] < by_scheme["upwind"]


def _scheme_targets(out):
    for row in rows(out / "scheme_targets.csv"):
        assert 0 < row["tip_err_mm"] < 50, row  # finite errors of the right scale at the smoke sizes


def _fetching_hold(out):
    table = {row["scheme"]: row for row in rows(out / "fetching_hold.csv")}
    for row in table.values():
        assert row["success"] and row["gap_end_mm"] < row["gap_at_8s_mm"], row  # the held arm settles
    assert table["centred"]["gap_end_mm"] < table["upwind"]["gap_end_mm"]


def _long_output(out):
    for row in rows(out / "long_output.csv"):
        assert row["success"] and row["frames"] == round(100 * row["t_end_s"]) + 1, row
        if row["format"] == "xdmf":
            assert row["files"] == 6 and row["megabytes"] > 0


def _stiff_cantilever(out):
    for row in rows(out / "stiff_cantilever.csv"):
        if row["success"] and row["t_reached"] > 0:  # the Euler-Bernoulli period within a few percent
            assert abs(row["period_error_pct"]) < 5, row
            if "galpha" in row["configuration"] and "rho_inf 1" in row["configuration"]:
                assert row["swing_energy_kept_pct"] > 99.0, row  # undamped: no numerical damping


def _core_speed(out):
    table = {row["key"]: row for row in rows(out / "core_speed.csv")}
    assert table["tip_max_diff_m"]["new_median"] < 1e-5  # the two versions compute the same motion
    assert 0.5 < table["steps"]["ratio_new_old_median"] < 2


def _view_open(out):
    for row in rows(out / "view_open.csv"):
        assert row["open_s"] > 0 and row["last_frame_s"] <= row["open_s"], row


def _closed_loop(out):
    table = {row["method"]: row for row in rows(out / "closed_loop.csv")}
    # the kept-alive stepper costs about the replay of the same table; the per-period workaround rebuilds it all
    assert table["Simulator"]["ratio_to_replay"] < table["per-period simulate"]["ratio_to_replay"]
    # held tensions: CVODE's steps are not cut at each period's end (counts, not times)
    held, one = table["Simulator, held tensions (50 Hz)"], table["simulate, the same tensions"]
    assert held["steps"] <= 1.2 * one["steps"] and held["restarts"] == 1 and held["tip_gap_m"] < 1e-4


def _inverse_statics(out):
    for row in rows(out / "inverse_statics.csv"):
        assert row["reachable"] and row["residual_m"] < 1e-4, row  # reachable targets met to 0.1 mm
        if row["case"].startswith("path"):
            assert row["ratio_to_forward"] < 5, row  # a path target costs a few forward equilibria at most


def _linear_mpc(out):
    for row in rows(out / "linear_mpc.csv"):
        errors = [row[f"error_{k}_pct"] for k in (4, 8, 16, 32) if f"error_{k}_pct" in row]
        assert errors == sorted(errors, reverse=True), row  # more modes kept, closer to the full model
        assert errors[-1] < 5, row


def _quaternion_norm(out):
    for row in rows(out / "quaternion_norm.csv"):
        # the projection keeps |Q| = 1 to round-off and leaves the motion where it was
        assert row["max_norm_error_with"] < 1e-12 < row["max_norm_error_without"], row
        assert row["tip_difference_m"] < 1e-6 and row["steps_with"] == row["steps_without"], row


def _sensitivity_accuracy(out):
    table = rows(out / "sensitivity_accuracy.csv")
    accuracy = [row for row in table if row["table"] == "accuracy"]
    tight = min(accuracy, key=lambda row: row["rtol"])
    assert all(tight[k] < 1e-4 for k in ("error_E", "error_CyCz", "error_11")), tight  # the target
    assert tight["error_E"] < max(row["error_E"] for row in accuracy)  # tighter tolerances, closer
    cost = [row for row in table if row["table"] == "cost" and row["run"] == "2 sensitivities"]
    assert cost and all(1.0 < row["ratio_to_plain"] < 10.0 for row in cost), cost


def _adjoint_cost(out):
    table = rows(out / "adjoint_cost.csv")
    accuracy = [row for row in table if row["table"] == "accuracy"]
    tight = min(accuracy, key=lambda row: row["rtol"])
    assert all(tight[k] < 1e-4 for k in tight if k.startswith("error_")), tight  # the target
    assert tight["error_knot5"] <= max(row["error_knot5"] for row in accuracy)  # tighter tolerances, closer
    cost = [row for row in table if row["table"] == "cost" and row["run"] != "plain"]
    assert cost and all(1.0 < row["ratio_to_plain"] < 30.0 for row in cost), cost


def _optimal_tensions(out):
    summary = [row for row in rows(out / "optimal_tensions.csv") if row["table"] == "summary"][0]
    assert summary["success"] is True and summary["rms_error_N"] < 0.05, summary  # the target
    assert summary["loss_end"] < 1e-6 * summary["loss_start"], summary


def _octopus_gait(out):
    gaits = [row for row in rows(out / "octopus_gait.csv") if row["table"] == "gaits"]
    hand, optimised = gaits
    assert hand["success"] is True and optimised["success"] is True, gaits
    assert optimised["dx_mm"] > hand["dx_mm"], gaits  # the target: farther than the hand-made crawl


def _octopus(out):
    table = rows(out / "octopus.csv")
    assert all(row["success"] is True for row in table), table
    one, octopus = table[0]["state_size"], table[-1]["state_size"]
    assert octopus == 8 * one + 13  # eight arms and a free head's block


def _system_stepping(out):
    table = {row["method"]: row for row in rows(out / "system_stepping.csv")}
    stepped = table["Simulator(System), 50 Hz"]
    assert stepped["head_gap_m"] < 1e-5  # the same equations as the table's simulate, to rtol
    assert stepped["restarts"] >= 1


def _octopus_stats(out):
    table = rows(out / "octopus_stats.csv")  # CVODE's counters read and checked against the run's count
    assert all(row["success"] is True for row in table), table
    for pattern in {row["pattern"] for row in table}:
        sizes = {row["case"]: row["state_size"] for row in table if row["pattern"] == pattern}
        one = sizes["one arm, System (GMRES)"]
        assert all(sizes[f"{k} arm{'s' if k > 1 else ''} + free head"] == k * one + 13 for k in (1, 2, 4, 8))


def _system_equilibrium_speed(out):
    table = rows(out / "system_equilibrium_speed.csv")  # both paths find the same rest; sparse needs less memory
    assert {row["jacobian"] for row in table} == {"sparse", "dense"}
    assert all(row["max_difference_over_scale"] < 1e-8 for row in table), table
    assert all(row["peak_vs_dense"] < 1.0 for row in table if row["jacobian"] == "sparse"), table


def _rest_strains_speed(out):
    with open(out / "rest_strains_speed.md") as f:  # the default rest strains change no number
        assert "tip trajectories bitwise equal: True" in f.read()
    assert {row["quantity"] for row in rows(out / "rest_strains_speed.csv")} >= {"integration wall time [s]"}


def _holds(out):
    table = rows(out / "holds.csv")
    assert all(row["success"] for row in table)
    for problem in {row["problem"] for row in table}:
        runs = sorted((row for row in table if row["problem"] == problem), key=lambda row: row["factor"])
        for soft, stiff in zip(runs, runs[1:]):  # the pin's drift is F / k: it falls as the factor grows
            ratio = soft["rest_drift_over_L"] / stiff["rest_drift_over_L"]
            np.testing.assert_allclose(ratio, stiff["factor"] / soft["factor"], rtol=0.2)
        assert all(row["steps_over_free"] < 3 for row in runs), runs


def _loops(out):
    table = rows(out / "loops.csv")
    assert {row["linear_solver"] for row in table} == {"gmres", "sparse"}
    assert all(row["success"] for row in table), table
    assert all(row["max_drift_over_L"] < 1e-4 for row in table), table  # the default factor or stiffer
    by_size = rows(out / "loops_by_size.csv")  # GMRES with the rod-rod joints' blocks against sparse
    assert {row["problem"] for row in by_size} == {"two half beams", "three rods", "ring"}
    assert all(row["success"] and row["rhs_ratio"] < 1.5 and row["max_difference_over_L"] < 1e-3
               for row in by_size), by_size


def _body_contact(out):
    example, untouched, resting = rows(out / "body_contact.csv")
    assert all(row["success"] is True for row in (example, untouched, resting))
    # a contact that does not touch (none does within the smoke run) adds nothing: the same run, step for step
    assert untouched["rhs_evals"] == example["rhs_evals"]
    assert untouched["head_gap_at_rest_mm"] == example["head_gap_at_rest_mm"]


def _body_joints(out):
    table = rows(out / "body_joints.csv")
    assert table and all(row["success"] for row in table if row["factor"] == 1.0), table
    assert all(row["max_drift_over_L"] < 1e-3 for row in table if row["factor"] == 1.0), table


def _system_output(out):
    (new,) = rows(out / "system_output.csv")  # the smoke run measures the working tree only
    assert new["version"] == "new" and new["chunks"] == 4
    # system.h5 an index of chunk files: it grows by a few bytes a chunk, not by the chunk's states
    # (the old one, rewritten whole, grew with every chunk: 400 kB to 24.5 MB over 80, docs/performance.md)
    assert new["index_last_kb"] < 1.2 * new["index_first_kb"]


def _rod_contact(out):
    table = rows(out / "rod_contact.csv")
    assert all(row["success"] is True for row in table)
    # the beam carries the resting ball's weight through the contact (measured within 3e-4)
    assert all(abs(row["force_over_weight"] - 1.0) < 5e-3 for row in table), table


def _plectoneme(out):
    runs = [row for row in rows(out / "plectoneme.csv") if row.get("steps") not in ("", None)]
    assert runs and all(row["success"] is True for row in runs)
    assert all(row["link_error_rel"] < 1e-2 for row in runs)  # the link follows the turns applied


def _rods_touching(out):
    table = {row["case"]: row for row in rows(out / "rods_touching.csv")}
    assert all(row["success"] is True for row in table.values())
    crossing = [row for case, row in table.items() if case.endswith(": contact")]
    assert crossing and all(row["least_gap_um"] < 0.0 for row in crossing)  # resting on the other rod
    declared = [row for case, row in table.items() if case.startswith("declared")]
    assert declared and all(row["pairs"] == 0 for row in declared)  # never touching


def _reach_scores(out):
    table = {row["policy"]: row for row in rows(out / "reach_scores.csv")}
    assert set(table) == {"random", "proportional", "inverse statics, open loop", "linear MPC", "successive linear MPC"}
    for row in table.values():  # a distance [m] of the reach, at most the arm's length from the target
        distances = [value for key, value in row.items() if key.endswith("_mm")]
        assert all(0.0 <= d < 1e3 for d in distances) and math.isfinite(row["mean_return"]), row


def _vtp_series_cost(out):
    table = rows(out / "vtp_series_cost.csv")
    collections = sorted((row for row in table if row["case"] == "collections"), key=lambda row: row["frames"])
    for row in table:  # after: whole writes only as the room doubles (logarithmic in frames)
        assert row["after_whole_writes"] <= 3 * (math.log2(row["frames"]) + 2), row
    # bytes: before grows as frames^2, after as frames
    first, last = collections[0], collections[-1]
    assert last["before_pvd_mb"] / last["after_pvd_mb"] > 1.5 * first["before_pvd_mb"] / first["after_pvd_mb"]
    assert all(row["after_collections_s"] >= 0 for row in table if row["case"] == "series")


def _driver_speed(out):
    table = {row["case"]: row for row in rows(out / "driver_speed.csv")}
    assert set(table) == {"octopus ramp", "octopus pulsing", "bending N=100"}
    for row in table.values():  # the same system through the three drivers: the same steps
        assert row["old_steps"] == row["main_steps"] == row["new_steps"], row
        assert row["new_vs_old"] > 0 and row["new_vs_main"] > 0
    bending = table["bending N=100"]  # a single rod's run keeps every counter of main's
    assert (bending["main_rhs_evals"], bending["main_linear_setups"]) == \
        (bending["new_rhs_evals"], bending["new_linear_setups"])


def _crawl_speed(out):
    table = rows(out / "crawl_speed.csv")
    assert {(row["case"], row["configuration"]) for row in table} == \
        {(case, name) for case in ("slack", "gait", "random") for name in ("main", "new, rtol 3e-5", "new")}
    for row in table:  # every configuration near the reference run at rtol 3e-6
        assert row["steps"] > 0 and row["cpu_per_sim_s"] > 0 and row["head_error_m"] < 1e-4, row


def _accuracy_per_cost(out):
    table = [row for row in rows(out / "accuracy_per_cost.csv") if row["default_rtol"]]
    errors = [row["tip_err_mm"] for row in sorted(table, key=lambda row: row["N"])]
    assert 0 < errors[-1] < errors[0] < 50, errors  # refining the default scheme reduces the error
    assert all(row["cpu_s"] > 0 and row["of_private_reference"] > 0 for row in table), table


def _step_overhead(out):
    for run in rows(out / "step_overhead_runs.csv"):
        # CVODE's steps: the one-step calls less those that handed a step back after outputs inside it
        assert run["onestep"] - run["repeats"] == run["steps"] and run["repeats"] <= run["interpolations"], run
        assert run["rhs"] >= run["newton"] >= run["steps"], run  # one right-hand side per Newton iteration at least


def _compiled_driver(out):
    for row in rows(out / "compiled_driver.csv"):  # the same algorithm with compiled callbacks: the same run
        assert row["compiled_steps"] == row["rodmol_steps"] and row["compiled_rhs"] == row["rodmol_rhs"], row
        assert row["tip_gap_m"] < 1e-9, row
        # and driven by rodmol's own Stepper (its watch, outputs and stop times), a drop-in solver
        assert row["rodmol_driver_compiled_steps"] == row["rodmol_steps"], row
        assert row["rodmol_driver_compiled_tip_gap_m"] < 1e-9, row


def _bending_vs_commit(out):
    table = {row["quantity"]: row for row in rows(out / "bending_vs_commit.csv")}
    assert 0.5 < table["steps"]["new_over_old_paired"] < 2
    with open(out / "bending_vs_commit.md") as f:  # the two versions compute the same motion
        gap = float(f.read().split("max |old - new| = ")[1].split(" m")[0])
    assert gap < 1e-5


def _cold_start(out):
    runs = rows(out / "cold_start.csv")
    cold = [r for r in runs if r["state"] == "cold"]
    warm = [r for r in runs if r["state"] == "warm"]
    assert cold and warm
    # A fresh tree compiles every kernel (in the run or its helper); the warm run loads them.
    assert min(r["self_cpu_s"] + r["helper_cpu_s"] for r in cold) > max(r["self_cpu_s"] + r["helper_cpu_s"] for r in warm)


SCRIPTS = {
    "scaling.py": (["scaling.csv", "scaling.md", "scaling.png", "scaling_extra.csv", "scaling_long.csv"], _scaling),
    "temporal.py": (["temporal.csv", "temporal.md", "temporal.png", "temporal_rk23.csv", "temporal_options.csv"],
                    _temporal),
    "work_precision.py": (["work_precision.csv", "work_precision.md", "work_precision.png"], _work_precision),
    "convergence.py": (["convergence.csv", "convergence.md", "convergence.png"], _convergence),
    "release.py": (["release.csv", "release.md"], _release),
    "profile_rhs.py": (["profile_rhs.csv", "profile_rhs_calls.csv", "profile_rhs_ladder.csv", "profile_rhs.md",
                        "profile_rhs.png"], _profile_rhs),
    "core_speed.py": (["core_speed.csv", "core_speed.md"], _core_speed),
    "continuum.py": (["continuum.csv", "continuum.md", "continuum.png"], _continuum),
    "schemes.py": (["schemes.csv", "schemes.md", "schemes.png"], _schemes),
    "scheme_targets.py": (["scheme_targets.csv", "scheme_targets.md"], _scheme_targets),
    "fetching_hold.py": (["fetching_hold.csv", "fetching_hold.md", "fetching_hold.png"], _fetching_hold),
    "long_output.py": (["long_output.csv", "long_output.md"], _long_output),
    "stiff_cantilever.py": (["stiff_cantilever.csv", "stiff_cantilever.md"], _stiff_cantilever),
    "view_open.py": (["view_open.csv", "view_open.md"], _view_open),
    "closed_loop.py": (["closed_loop.csv", "closed_loop.md"], _closed_loop),
    "inverse_statics.py": (["inverse_statics.csv", "inverse_statics.md"], _inverse_statics),
    "linear_mpc.py": (["linear_mpc.csv", "linear_mpc.md"], _linear_mpc),
    "reach_scores.py": (["reach_scores.csv", "reach_scores.md"], _reach_scores),
    "quaternion_norm.py": (["quaternion_norm.csv", "quaternion_norm.md"], _quaternion_norm),
    "octopus.py": (["octopus.csv", "octopus.md"], _octopus),
    "sensitivity_accuracy.py": (["sensitivity_accuracy.csv", "sensitivity_accuracy.md"], _sensitivity_accuracy),
    "adjoint_cost.py": (["adjoint_cost.csv", "adjoint_cost.md"], _adjoint_cost),
    "optimal_tensions.py": (["optimal_tensions.csv", "optimal_tensions.md", "optimal_tensions.png"],
                            _optimal_tensions),
    "octopus_gait.py": (["octopus_gait.csv", "octopus_gait.md", "octopus_gait.png"], _octopus_gait),
    "octopus_stats.py": (["octopus_stats.csv", "octopus_stats.md"], _octopus_stats),
    "system_stepping.py": (["system_stepping.csv", "system_stepping.md"], _system_stepping),
    "system_equilibrium_speed.py": (["system_equilibrium_speed.csv", "system_equilibrium_speed.md"],
                                    _system_equilibrium_speed),
    "rest_strains_speed.py": (["rest_strains_speed.csv", "rest_strains_speed.md"], _rest_strains_speed),
    "holds.py": (["holds.csv", "holds.md"], _holds),
    "loops.py": (["loops.csv", "loops.md", "loops_by_size.csv"], _loops),
    "body_contact.py": (["body_contact.csv", "body_contact.md"], _body_contact),
    "body_joints.py": (["body_joints.csv", "body_joints.md"], _body_joints),
    "system_output.py": (["system_output.csv", "system_output.md"], _system_output),
    "rod_contact.py": (["rod_contact.csv", "rod_contact.md"], _rod_contact),
    "rods_touching.py": (["rods_touching.csv", "rods_touching.md"], _rods_touching),
    "plectoneme.py": (["plectoneme.csv", "plectoneme.md"], _plectoneme),
    "vtp_series_cost.py": (["vtp_series_cost.csv", "vtp_series_cost.md"], _vtp_series_cost),
    "driver_speed.py": (["driver_speed.csv", "driver_speed.md", "driver_speed_runs.csv"], _driver_speed),
    "crawl_speed.py": (["crawl_speed.csv", "crawl_speed.md", "crawl_speed_runs.csv"], _crawl_speed),
    "accuracy_per_cost.py": (["accuracy_per_cost.csv", "accuracy_per_cost.md"], _accuracy_per_cost),
    "step_overhead.py": (["step_overhead.csv", "step_overhead_runs.csv", "step_overhead_calls.csv",
                          "step_overhead.md"], _step_overhead),
    "bending_vs_commit.py": (["bending_vs_commit.csv", "bending_vs_commit.md"], _bending_vs_commit),
    "compiled_driver.py": (["compiled_driver.csv", "compiled_driver.md"], _compiled_driver),
    "cold_start.py": (["cold_start.csv", "cold_start.md"], _cold_start),
}


#: Scripts that start subprocesses themselves: the trees they compare, or a fresh run each.
SPAWNING = {"bending_vs_commit.py", "cold_start.py", "core_speed.py", "long_output.py", "rest_strains_speed.py",
            "rods_touching.py", "system_output.py", "view_open.py", "driver_speed.py", "crawl_speed.py"}
#: The script run as a command: one of the quickest.
COMMAND = "release.py"


def _skip_without_what_it_needs(script):
    if script == "core_speed.py" and subprocess.run(
            ["git", "-C", ROOT, "cat-file", "-e", "9fce6d7^{commit}"], capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout holding commit 9fce6d7")
    if script == "bending_vs_commit.py" and subprocess.run(
            ["git", "-C", ROOT, "cat-file", "-e", "f8094e2^{commit}"], capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout holding commit f8094e2")
    if script == "system_output.py" and subprocess.run(
            ["git", "-C", ROOT, "cat-file", "-e", "06aa966^{commit}"], capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout holding commit 06aa966")
    if script in ("rest_strains_speed.py", "rods_touching.py") and subprocess.run(
            ["git", "-C", ROOT, "merge-base", "HEAD", "main"], capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout with a main branch (the base it measures against)")
    if script in ("driver_speed.py", "crawl_speed.py") and subprocess.run(
            ["git", "-C", ROOT, "merge-base", "HEAD", "main"], capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout with a main branch (the base it measures against)")
    if script == "driver_speed.py" and subprocess.run(
            ["git", "-C", ROOT, "cat-file", "-e", "548824c^{commit}"], capture_output=True).returncode != 0:
        pytest.skip("needs a git checkout holding commit 548824c")
    if script in ("reach_scores.py", "crawl_speed.py"):
        pytest.importorskip("gymnasium")
    if script == "view_open.py" and shutil.which("pvpython") is None:
        pytest.skip("needs ParaView's pvpython")


def _check_outputs(script, out):
    files, check = SCRIPTS[script]
    for name in files:
        path = out / name
        assert path.is_file() and path.stat().st_size > 0, name
    markdown = next(name for name in files if name.endswith(".md"))
    with open(out / markdown) as f:
        text = f.read()
    assert "machine:" in text and "numba" in text  # the header names the machine and versions
    check(out)


def _main(script):
    """The ``main`` of solvers/``script``, imported as the script's siblings import one another."""
    solvers = os.path.join(ROOT, "solvers")
    if sys.path[0] != solvers:  # first: examples/ holds namesakes (octopus.py)
        if solvers in sys.path:
            sys.path.remove(solvers)
        sys.path.insert(0, solvers)
    return importlib.import_module(script.removesuffix(".py")).main


#: Scripts whose smoke run takes tens of seconds (an optimisation of many runs; compiling
#: every kernel afresh) or several seconds for a study of speed alone (the compiled-callback
#: driver compiles its own callbacks; the side-by-side drivers start a worker per version):
#: kept out of the default run to hold it under 5 minutes (`-m slow` runs them).
SLOW = {"optimal_tensions.py", "octopus_gait.py", "cold_start.py", "compiled_driver.py", "rods_touching.py",
        "driver_speed.py", "crawl_speed.py", "bending_vs_commit.py"}


def _marks(script):
    marks = [pytest.mark.subprocess] * (script in SPAWNING) + [pytest.mark.slow] * (script in SLOW)
    return pytest.param(script, marks=marks)


@pytest.mark.parametrize("script", [_marks(s) for s in sorted(SCRIPTS) if s != COMMAND])
def test_script_smoke_run(script, tmp_path):
    _skip_without_what_it_needs(script)
    _main(script)(["--smoke", "--out", str(tmp_path)])
    _check_outputs(script, tmp_path)


@pytest.mark.subprocess
def test_script_smoke_run_as_a_command(tmp_path):
    proc = subprocess.run([sys.executable, os.path.join(ROOT, "solvers", COMMAND), "--smoke",
                           "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-4000:]
    _check_outputs(COMMAND, tmp_path)
