"""examples/python/plot_trajectory.py — an estimated trajectory drawn over its ground truth.

Usage: plot_trajectory.py GROUND_TRUTH ESTIMATE [OUT.png] [--align se3|sim3]
Both files in TUM, KITTI or EuRoC form (detected). Aligns the estimate with orbis.eval.ate (the
numbers of `orbis eval ate`) and writes a PNG (matplotlib, Agg backend: no display needed): left,
a top view on the two axes along which the ground truth extends most (the part of it
the estimate spans); right, the position error
over time with its RMSE.
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import orbis  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("ground_truth"), parser.add_argument("estimate")
    parser.add_argument("out", nargs="?", default="trajectory.png")
    parser.add_argument("--align", default="se3", choices=["se3", "sim3"])
    a = parser.parse_args()
    gt = orbis.read_trajectory(a.ground_truth)
    ate = orbis.eval.ate(gt, a.estimate, align=a.align)
    aligned = ate.aligned_estimate
    start, end = aligned[0, 0] - 1.0, aligned[-1, 0] + 1.0  # the ground truth the run covers, 1 s margin
    gt = gt[(gt[:, 0] >= start) & (gt[:, 0] <= end)]
    axes = np.argsort(np.ptp(gt[:, 1:4], axis=0))[::-1][:2]  # the two axes of largest extent
    names = np.array(["x", "y", "z"])[axes]

    figure, (top, error) = plt.subplots(1, 2, figsize=(12, 5))
    top.plot(gt[:, 1 + axes[0]], gt[:, 1 + axes[1]], color="0.6", label="ground truth")
    top.plot(aligned[:, 1 + axes[0]], aligned[:, 1 + axes[1]], color="tab:blue", label=f"estimate ({a.align})")
    top.set(xlabel=f"{names[0]} [m]", ylabel=f"{names[1]} [m]", aspect="equal", title="top view")
    top.legend()
    error.plot(aligned[:, 0] - aligned[0, 0], ate.errors * 1000, color="tab:red")
    error.axhline(ate.rmse * 1000, color="k", linestyle="--", label=f"RMSE {ate.rmse * 1000:.1f} mm")
    error.set(xlabel="time [s]", ylabel="position error [mm]", title=f"ATE over {ate.count} poses")
    error.legend()
    figure.tight_layout()
    figure.savefig(a.out, dpi=100)
    print(f"ATE {ate.rmse * 1000:.2f} mm over {ate.count} poses; plot written to {a.out}")


if __name__ == "__main__":
    main()
