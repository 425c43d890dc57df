"""From camera data to identified parameters: the paper's section V-C workflow
on the project's synthetic fetching experiment (examples/synthetic_experiment/).

1. calibrate each camera's 11 DLT parameters on the 8 control points (eq. 14);
2. triangulate the 4 markers from the two cameras' pixel tracks;
3. run the paper's model (Table I-III values) driven by the measured tension
   log and report the errors of eq. (15) (Table IV) and the worsened models
   (Table V);
4. identify E, mu and Cy = Cz by bounded least squares on a dask LocalCluster,
   and report them with their uncertainties and the errors before and after.

    python examples/identify_from_cameras.py [--figures DIR] [--serial] [--workers N] [--quick]

Runs in under a minute on 2 cores (``--quick``: the first 2 s of
the recording, E and Cy only, no Table V; about 15 s). The true parameters of the synthetic
"prototype" are in synthetic_experiment/truth.json (the script compares).
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np

import rodmol
from rodmol.calibrate import (
    MarkerTracks,
    PixelTracks,
    apply,
    calibrate_dlt,
    identify,
    paper_errors,
    plot_errors,
    read_control_points,
    read_marker_tracks,
    read_pixel_tracks,
    read_tension_log,
    reprojection_errors,
    triangulate,
    worsened_models,
)
from rodmol.calibrate.paper_errors import table
from rodmol.scenario.file import parse_scenario

DATA = Path(__file__).resolve().parent / "synthetic_experiment"
CAMERAS = ("front", "top")
#: What to fit, with bounds wide enough for a silicone arm in water.
PARAMETERS = {"material.E": (30e3, 400e3), "material.mu": (30.0, 3000.0), "medium.Cy,Cz": (0.3, 10.0)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA, help="folder of the experiment's CSV files")
    parser.add_argument("--figures", type=Path, help="write the error plots (PNG) here")
    parser.add_argument("--quick", action="store_true", help="first 2 s, E and Cy only, no Table V")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--serial", action="store_true", help="run without dask")
    where.add_argument("--workers", type=int, help="LocalCluster workers (default: one per core)")
    args = parser.parse_args()
    client = "serial" if args.serial else None
    truth = json.loads((args.data / "truth.json").read_text())
    started = time.perf_counter()

    # 1-2. Stereo reconstruction.
    cameras, pixels = [], []
    for name in CAMERAS:
        xyz, uv = read_control_points(args.data / f"control_{name}.csv")
        cameras.append(calibrate_dlt(xyz, uv, name=name))
        pixels.append(read_pixel_tracks(args.data / f"pixels_{name}.csv"))
    measured = triangulate(cameras, pixels)
    if args.quick:
        keep = measured.t <= 2.0
        measured = MarkerTracks(measured.t[keep], measured.xyz[keep], measured.names)
        pixels = [PixelTracks(p.t[keep], p.uv[keep], p.names) for p in pixels]
    reprojection = reprojection_errors(cameras, pixels, measured)
    print("1. DLT calibration on 8 control points (eq. 14): reprojection rms "
          + ", ".join(f"{c.name} {c.rms:.2f} px" for c in cameras))
    seen = np.all(np.isfinite(measured.xyz), axis=-1)
    print(f"2. triangulated {measured.xyz.shape[1]} markers x {len(measured.t)} samples "
          f"({100 * np.mean(~seen):.1f}% occluded in a camera); marker reprojection rms "
          f"{np.sqrt(np.nanmean(reprojection**2)):.2f} px")
    true_markers = read_marker_tracks(args.data / "true_markers.csv")
    error = np.linalg.norm(measured.xyz - true_markers.xyz[:len(measured.t)], axis=-1)
    print(f"   reconstruction error against the synthetic truth: rms {1e3 * np.sqrt(np.nanmean(error**2)):.2f} mm")

    # 3. The paper's model, driven by the measured tensions.
    text = f'name = "fetching"\narm = "paper"\nscenario = "fetching"\n' \
           f'[discretization]\nn_elements = {truth["n_elements"]}\nscheme = "{truth["scheme"]}"\n'
    log = read_tension_log(args.data / "tensions.csv", clip_negative=True)
    spec = apply(parse_scenario(text), log.overrides())
    if args.quick:
        spec = apply(spec, {"solver.t_end": float(measured.t[-1])})
    nominal = spec.simulate()
    table4 = paper_errors(nominal, measured, name="fetching, paper's parameters")
    print("\n3. Table IV (eq. 15, time averages), the paper's parameters:\n" + table([table4], "Test"))
    study = None if args.quick else worsened_models(spec, measured, client=client, n_workers=args.workers)
    if study:
        print("\n   Table V (worsened models, same data):\n" + study.table())

    # 4. Identification.
    parameters = {k: v for k, v in PARAMETERS.items() if not (args.quick and k == "material.mu")}
    fit = identify(spec, measured, parameters, client=client, n_workers=args.workers,
                   progress=lambda i, cost: print(f"   iteration {i}: cost {cost:.4g}"))
    true = {k: truth["parameters"][k] for k in parameters}
    print("\n4. Identified parameters (start: the paper's values; truth: the synthetic prototype's):\n"
          + fit.table(true))
    fitted = apply(spec, fit.values).simulate()
    after = paper_errors(fitted, measured, name="fetching, identified parameters")
    print("\n   Table IV after identification:\n" + table([table4, after], "Test"))
    if args.figures:
        args.figures.mkdir(parents=True, exist_ok=True)
        plot_errors([table4, after], args.figures / "calibration_errors.png",  # the figures made anew
                    "Synthetic fetching test: errors of eq. (15)", overwrite=True)
        print(f"\nwrote {args.figures / 'calibration_errors.png'}")
        if study:
            study.plot(args.figures / "calibration_table5.png",
                       "Worsened models (Table V), synthetic fetching", overwrite=True)
            print(f"wrote {args.figures / 'calibration_table5.png'}")
    print(f"\ndone in {time.perf_counter() - started:.0f} s (rodmol {rodmol.__version__})")


if __name__ == "__main__":
    main()
