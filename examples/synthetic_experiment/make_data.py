"""Make the synthetic experiment in this folder (run it to regenerate the files).

There are no published recordings of the paper's prototype, so this is a
recording made by the project: the paper's fetching test (our reading of its
tensions) run at N = 20 (centred scheme) with perturbed parameters, its four
markers seen by two synthetic cameras with known DLT parameters (1 px of
noise, 1% of the samples occluded in each camera), eight control points (0.1 px: fixed markers whose
centroids are averaged over the recording), and the tension log with 0.02 N of
sensor noise. See README.md.
"""

import json
from pathlib import Path

import rodmol
from rodmol.calibrate import (
    synthetic,
    write_control_points,
    write_marker_tracks,
    write_pixel_tracks,
    write_tension_log,
)
from rodmol.scenario.file import parse_scenario

HERE = Path(__file__).resolve().parent
N_ELEMENTS = 20
SCHEME = "centred"
#: The parameters of the "prototype": the paper's, perturbed.
TRUTH = {"material.E": 95e3, "material.mu": 380.0, "medium.Cy,Cz": 2.9}


def main():
    spec = parse_scenario(f'name = "fetching"\narm = "paper"\nscenario = "fetching"\n'
                          f'[discretization]\nn_elements = {N_ELEMENTS}\nscheme = "{SCHEME}"\n')
    rec = synthetic.synthesize(spec, TRUTH, noise_px=1.0, tension_noise=0.02, occlusion=0.01, seed=2014)
    for cam, uv, pixels in zip(rec.cameras, rec.control_uv, rec.pixels):  # made anew: replaced
        write_control_points(HERE / f"control_{cam.name}.csv", rec.control_xyz, uv, overwrite=True)
        write_pixel_tracks(HERE / f"pixels_{cam.name}.csv", pixels, overwrite=True)
    write_tension_log(HERE / "tensions.csv", rec.tensions, overwrite=True)
    write_marker_tracks(HERE / "true_markers.csv", rec.true_markers, overwrite=True)
    (HERE / "truth.json").write_text(json.dumps(dict(
        scenario="fetching", n_elements=N_ELEMENTS, scheme=SCHEME, parameters=TRUTH,
        rodmol=rodmol.__version__,
        cameras={c.name: c.H.tolist() for c in rec.cameras}, noise_px=1.0, control_noise_px=0.1,
        tension_noise_N=0.02, occlusion=0.01, seed=2014), indent=2) + "\n")
    print(f"wrote the synthetic fetching experiment to {HERE}")


if __name__ == "__main__":
    main()
