"""Solve for a target shape (the bar bent up and sideways) with both optimizers and plot how the
shape error fell, per iteration and over time, to a PNG.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/solve_convergence.py --out convergence.png
"""

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402

import shapectl  # noqa: E402
from bar_shapes import argument_parser, bent_centerline  # noqa: E402


def main():
    parser = argument_parser(__doc__)
    parser.add_argument("--lift", type=float, default=0.04, help="bend up at mid-bar, m")
    parser.add_argument("--shift", type=float, default=0.02, help="bend sideways, m")
    parser.add_argument("--out", default="convergence.png", help="the plot (PNG)")
    args = parser.parse_args()

    scene = shapectl.Scene.load(args.scene)
    targets = bent_centerline(scene, args.lift, args.shift)
    figure, (by_iteration, by_time) = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for optimizer in ("gauss-newton", "lbfgs"):
        result = shapectl.solve(scene, targets, optimizer=optimizer, max_iterations=100)
        errors_mm = [1e3 * h.error_mean for h in result.history]
        by_iteration.semilogy([h.iteration for h in result.history], errors_mm, marker=".",
                              label=f"{optimizer} ({result.termination})")
        by_time.semilogy([h.time for h in result.history], errors_mm, marker=".", label=optimizer)
        print(f"{optimizer}: {result.termination}, mean error {1e3 * result.error_mean:.2f} mm "
              f"after {result.iterations} iterations, {result.history[-1].time:.2f} s")
    by_iteration.set(xlabel="iteration", ylabel="mean distance from the targets (mm)")
    by_time.set(xlabel="time (s)")
    for axes in (by_iteration, by_time):
        axes.axhline(1.0, color="grey", linestyle=":", linewidth=1)
        axes.grid(True, which="both", alpha=0.3)
        axes.legend()
    figure.suptitle(f"bar bent {1e3 * args.lift:.0f} mm up, {1e3 * args.shift:.0f} mm sideways")
    figure.tight_layout()
    figure.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
