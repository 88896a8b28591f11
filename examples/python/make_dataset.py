"""Generate a small (θ, shape) dataset for learning: random joints around the reference pose,
the bar's equilibrium at each, to one .npz. Samples whose statics do not converge or whose pose
collides with itself are left out (and counted).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/make_dataset.py --samples 200 --out bar.npz

The file: joints (N, m) rad, positions (N, n, 3) m, min_clearance (N,) m, joint_names (m,),
rest_positions (n, 3), tets (t, 4).
"""

import numpy as np

import shapectl
from bar_shapes import argument_parser


def main():
    parser = argument_parser(__doc__)
    parser.add_argument("--samples", type=int, default=200, help="joint samples to try")
    parser.add_argument("--spread", type=float, default=0.05,
                        help="each joint uniform within ± this of its reference, rad")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="dataset.npz")
    args = parser.parse_args()

    scene = shapectl.Scene.load(args.scene)
    robot = scene.robot
    rng = np.random.default_rng(args.seed)
    joints, positions, clearances = [], [], []
    unconverged = colliding = 0
    for _ in range(args.samples):
        theta = scene.reference_joints + rng.uniform(-args.spread, args.spread, len(robot.joint_names))
        theta = np.clip(theta, robot.lower_limits, robot.upper_limits)
        clearance = shapectl.kinematics(scene, theta).min_clearance
        if clearance is not None and clearance <= 0:
            colliding += 1
            continue
        equilibrium = shapectl.statics(scene, theta)
        if not equilibrium.converged:
            unconverged += 1
            continue
        joints.append(theta)
        positions.append(equilibrium.positions)
        clearances.append(np.inf if clearance is None else clearance)
    np.savez(args.out, joints=np.array(joints).reshape(-1, len(robot.joint_names)),
             positions=np.array(positions).reshape(-1, scene.node_count, 3),
             min_clearance=np.array(clearances), joint_names=np.array(scene.joint_names),
             rest_positions=scene.rest_positions, tets=scene.tets)
    print(f"wrote {args.out}: {len(joints)} samples ({unconverged} not converged, "
          f"{colliding} self-colliding left out)")


if __name__ == "__main__":
    main()
