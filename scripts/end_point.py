#!/usr/bin/python3
"""End-point error of an estimate against ground truth, both anchored at their first common pose (what a
robot that starts at a known pose ends up off by), as a percentage of the distance driven.
  end_point.py GT.tum EST.tum [NAME] [APE]"""
import sys
import numpy as np


def read_tum(path):
    rows = [l.split() for l in open(path) if l.strip() and not l.startswith("#")]
    return {round(float(r[0]), 4): np.array([float(x) for x in r[1:8]]) for r in rows}


def matrix(p):
    x, y, z, qx, qy, qz, qw = p
    R = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                  [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                  [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, [x, y, z]
    return T


gt, est = read_tum(sys.argv[1]), read_tum(sys.argv[2])
times = sorted(set(gt) & set(est))
g0, e0 = np.linalg.inv(matrix(gt[times[0]])), np.linalg.inv(matrix(est[times[0]]))
truth = (g0 @ matrix(gt[times[-1]]))[:3, 3]
estimate = (e0 @ matrix(est[times[-1]]))[:3, 3]
pts = np.array([gt[t][:3] for t in times])
distance = float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
error = float(np.linalg.norm(truth - estimate))
name = sys.argv[3] if len(sys.argv) > 3 else sys.argv[2]
ape = f"   APE rmse {sys.argv[4]} m" if len(sys.argv) > 4 else ""
print(f"{name:<40} end-point {error:8.2f} m = {100 * error / distance:6.2f} % of {distance:7.1f} m "
      f"(estimate {np.linalg.norm(estimate):7.1f} m from the start, truth {np.linalg.norm(truth):7.1f} m){ape}")
