#!/usr/bin/python3
"""Plots for `adit eval` and the demo report (called by lib/eval/plot.cpp; Agg backend, no display).

  plot_trajectory.py trajectory DATA.txt OUT.png TITLE
      DATA.txt columns: t_s gt_x gt_y gt_z est_x est_y est_z ape_m ('#' header).
      Left: top view (x-y) of ground truth and the aligned estimate coloured by APE, with a colour bar.
      Right: APE over time with its rmse, mean and median.
  plot_trajectory.py map POINTS.bin OUT.png TITLE [TRAJ.txt]
      POINTS.bin: float32 x y z triples. TRAJ.txt: "x y" per line (may be empty).
      Top view of the map as a point-density image, trajectory drawn over it.

Exit codes: 0 ok, 2 bad arguments or data, 3 matplotlib/numpy missing.
"""
import os
import sys


def fail(code, message):
    sys.stderr.write(message + "\n")
    sys.exit(code)


try:
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from matplotlib.colors import LogNorm
except ImportError as e:
    fail(3, "python3-matplotlib / python3-numpy missing (%s): apt-get install python3-matplotlib" % e)


def plot_trajectory(data_path, out_path, title):
    d = np.loadtxt(data_path, ndmin=2)
    if d.shape[0] == 0 or d.shape[1] != 8:
        fail(2, "trajectory data must have 8 columns and at least one row")
    t, gt, est, err = d[:, 0], d[:, 1:4], d[:, 4:7], d[:, 7]
    fig, (ax_top, ax_err) = plt.subplots(1, 2, figsize=(14, 6), gridspec_kw={"width_ratios": [1.2, 1]})
    fig.suptitle(title)

    ax_top.plot(gt[:, 0], gt[:, 1], "--", color="0.4", lw=1.2, label="ground truth")
    norm = plt.Normalize(float(err.min()), float(max(err.max(), err.min() + 1e-9)))
    if len(est) >= 2:
        segments = np.stack([est[:-1, :2], est[1:, :2]], axis=1)
        lines = LineCollection(segments, cmap="jet", norm=norm, linewidths=2.0)
        lines.set_array(0.5 * (err[:-1] + err[1:]))
        ax_top.add_collection(lines)
        mappable = lines
    else:
        mappable = ax_top.scatter(est[:, 0], est[:, 1], c=err, cmap="jet", norm=norm)
    ax_top.plot([], [], color="tab:red", lw=2, label="estimate (colour = APE)")
    ax_top.plot(gt[0, 0], gt[0, 1], "ko", ms=5, label="start")
    fig.colorbar(mappable, ax=ax_top, label="APE (m)")
    ax_top.set_xlabel("x (m)")
    ax_top.set_ylabel("y (m)")
    ax_top.set_aspect("equal", adjustable="datalim")
    ax_top.autoscale_view()
    ax_top.grid(True, alpha=0.3)
    ax_top.legend(loc="best", fontsize=8)
    ax_top.set_title("top view")

    rmse = float(np.sqrt(np.mean(err ** 2)))
    ax_err.plot(t, err, color="tab:blue", lw=1.0, label="APE")
    ax_err.axhline(rmse, color="tab:red", lw=1, label="rmse %.3f m" % rmse)
    ax_err.axhline(float(np.mean(err)), color="tab:green", lw=1, ls="--", label="mean %.3f m" % np.mean(err))
    ax_err.axhline(float(np.median(err)), color="tab:orange", lw=1, ls=":", label="median %.3f m" % np.median(err))
    ax_err.set_xlabel("time (s)")
    ax_err.set_ylabel("APE (m)")
    ax_err.grid(True, alpha=0.3)
    ax_err.legend(loc="best", fontsize=8)
    ax_err.set_title("APE over time")
    fig.tight_layout()
    save(fig, out_path)


def plot_map(points_path, out_path, title, traj_path):
    pts = np.fromfile(points_path, dtype=np.float32)
    if pts.size == 0 or pts.size % 3:
        fail(2, "map data must be float32 x y z triples")
    pts = pts.reshape(-1, 3)
    x, y = pts[:, 0].astype(float), pts[:, 1].astype(float)
    span = max(x.max() - x.min(), y.max() - y.min(), 1.0)
    cell = max(span / 1200.0, 0.02)  # about 1200 cells across, never finer than 2 cm
    nx = max(int((x.max() - x.min()) / cell) + 1, 1)
    ny = max(int((y.max() - y.min()) / cell) + 1, 1)
    counts, xe, ye = np.histogram2d(x, y, bins=[nx, ny])
    fig, ax = plt.subplots(figsize=(10, 10 * min(max(ny / nx, 0.3), 3.0)))
    masked = np.ma.masked_equal(counts.T, 0)
    image = ax.imshow(masked, origin="lower", extent=[xe[0], xe[-1], ye[0], ye[-1]], cmap="viridis",
                      norm=LogNorm(vmin=1, vmax=max(counts.max(), 2)), interpolation="nearest")
    fig.colorbar(image, ax=ax, label="points per %.2f m cell" % cell, shrink=0.8)
    if traj_path:
        tr = np.loadtxt(traj_path, ndmin=2)
        if tr.size:
            ax.plot(tr[:, 0], tr[:, 1], color="tab:red", lw=1.2, label="trajectory")
            ax.legend(loc="best", fontsize=8)
    ax.set_facecolor("white")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal")
    ax.set_title("%s (%d points)" % (title, pts.shape[0]))
    fig.tight_layout()
    save(fig, out_path)


def save(fig, out_path):
    """Write atomically: a reader never sees a half-written PNG."""
    tmp = out_path + ".tmp"
    fig.savefig(tmp, dpi=110, format="png")
    os.replace(tmp, out_path)


def main(argv):
    if len(argv) >= 4 and argv[1] == "trajectory":
        plot_trajectory(argv[2], argv[3], argv[4] if len(argv) > 4 else "")
    elif len(argv) >= 4 and argv[1] == "map":
        plot_map(argv[2], argv[3], argv[4] if len(argv) > 4 else "Map", argv[5] if len(argv) > 5 else "")
    else:
        fail(2, __doc__)


if __name__ == "__main__":
    try:
        main(sys.argv)
    except Exception as e:  # one clear line for the C++ caller instead of a traceback
        fail(2, "%s: %s" % (type(e).__name__, e))
