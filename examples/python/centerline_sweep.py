"""Sweep a family of centre-lines (the bar's middle raised further and further, straight up and
sideways) and chart how close the robot can bring the bar to each: the reachable error.
Writes the chart (PNG) and the numbers (.npz beside it).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/centerline_sweep.py --out sweep.png
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import shapectl  # noqa: E402
from bar_shapes import argument_parser, bent_centerline  # noqa: E402


def main():
    parser = argument_parser(__doc__)
    parser.add_argument("--max-lift", type=float, default=0.12, help="largest bend, m")
    parser.add_argument("--steps", type=int, default=13, help="bends from 0 to --max-lift")
    parser.add_argument("--out", default="sweep.png", help="the chart (PNG); NAME.npz beside")
    args = parser.parse_args()

    scene = shapectl.Scene.load(args.scene)
    lifts = np.linspace(0.0, args.max_lift, args.steps)
    directions = {"up": (1.0, 0.0), "up and sideways": (np.sqrt(0.5), np.sqrt(0.5))}
    figure, axes = plt.subplots(figsize=(7, 4.5))
    columns = {"lift": lifts}
    for name, (up, sideways) in directions.items():
        results = [shapectl.solve(scene, bent_centerline(scene, up * d, sideways * d),
                                  max_iterations=50) for d in lifts]
        key = name.replace(" ", "_")
        columns[f"{key}_error_mean"] = np.array([r.error_mean for r in results])
        columns[f"{key}_error_max"] = np.array([r.error_max for r in results])
        columns[f"{key}_converged"] = np.array([r.converged for r in results])
        [mean] = axes.plot(1e3 * lifts, 1e3 * columns[f"{key}_error_mean"], marker="o",
                           label=f"{name}: mean")
        axes.plot(1e3 * lifts, 1e3 * columns[f"{key}_error_max"], linestyle="--",
                  color=mean.get_color(), label=f"{name}: max")
    axes.axhline(1.0, color="grey", linestyle=":", linewidth=1, label="1 mm")
    axes.set(xlabel="bend at mid-bar (mm)", ylabel="distance from the centre-line (mm)",
             title="How far the bar can be bent: the reachable error")
    axes.grid(True, alpha=0.3)
    axes.legend()
    figure.tight_layout()
    figure.savefig(args.out, dpi=100)
    numbers = Path(args.out).with_suffix(".npz")
    np.savez(numbers, **columns)
    print(f"wrote {args.out} and {numbers}")


if __name__ == "__main__":
    main()
