#!/usr/bin/python3
"""Independent numpy re-implementation of the evo / KITTI-devkit definitions adit's lib/eval follows,
written from their documented behaviour (not shared code with the C++), used by test_evo_reference.cpp.

  evo_reference.py GT.tum EST.tum none|se3|sim3  ->  prints "key value" lines

Definitions (evo 1.x): sync.associate_trajectories (shorter trajectory searches the longer with argmin,
max diff 0.01 s), geometry.umeyama_alignment (with_scale for sim3) applied as p' = R (s p) + t,
APE translation_part stats with np.std / np.median, RPE translation_part / rotation_angle_deg with
delta in metres, consecutive pairs (filters.filter_pairs_by_path, all_pairs=False) chosen on the
aligned estimate; KITTI devkit calcSequenceErrors with step 10 and lengths 100..800 m.
"""
import sys

import numpy as np


def read_tum(path):
    d = np.loadtxt(path, comments="#", ndmin=2)
    poses = []
    for row in d:
        x, y, z, w = row[4], row[5], row[6], row[7]
        n = np.sqrt(x * x + y * y + z * z + w * w)
        x, y, z, w = x / n, y / n, z / n, w / n
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                      [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                      [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
        T = np.eye(4)
        T[:3, :3] = R
        T[:3, 3] = row[1:4]
        poses.append(T)
    return d[:, 0], poses


def associate(t_gt, gt, t_est, est, max_diff=0.01):
    est_longer = len(t_est) > len(t_gt)
    t_short, t_long = (t_gt, t_est) if est_longer else (t_est, t_gt)
    pairs = []
    for i, t in enumerate(t_short):
        diffs = np.abs(t_long - t)
        j = int(np.argmin(diffs))
        if diffs[j] <= max_diff:
            pairs.append((i, j))
    if est_longer:
        return [gt[i] for i, _ in pairs], [est[j] for _, j in pairs]
    return [gt[j] for _, j in pairs], [est[i] for i, _ in pairs]


def umeyama(x, y, with_scale):
    n = x.shape[1]
    mx, my = x.mean(axis=1), y.mean(axis=1)
    sigma = np.sum((x - mx[:, None]) ** 2) / n
    cov = (y - my[:, None]) @ (x - mx[:, None]).T / n
    u, d, vt = np.linalg.svd(cov)
    s = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        s[2, 2] = -1
    r = u @ s @ vt
    c = np.trace(np.diag(d) @ s) / sigma if with_scale else 1.0
    return r, my - c * r @ mx, c


def angle(R):
    return np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))


def stats(prefix, e):
    e = np.asarray(e, dtype=float)
    print(prefix + ".count", e.size)
    if e.size == 0:
        return
    for name, v in (("max", e.max()), ("min", e.min()), ("mean", e.mean()), ("median", np.median(e)),
                    ("rmse", np.sqrt(np.mean(e ** 2))), ("std", np.std(e))):
        print("%s.%s %.17g" % (prefix, name, v))


def path_pairs(poses, delta):
    ids, acc = [], 0.0
    for i in range(len(poses)):
        if i > 0:
            acc += np.linalg.norm(poses[i][:3, 3] - poses[i - 1][:3, 3])
        if acc >= delta:
            ids.append(i)
            acc = 0.0
    return list(zip(ids, ids[1:]))


def main(gt_path, est_path, mode):
    t_gt, gt = read_tum(gt_path)
    t_est, est = read_tum(est_path)
    gt, est = associate(t_gt, gt, t_est, est)
    print("matched", len(gt))
    if mode != "none":
        r, t, c = umeyama(np.array([p[:3, 3] for p in est]).T, np.array([p[:3, 3] for p in gt]).T, mode == "sim3")
        print("scale %.17g" % c)
        aligned = []
        for p in est:
            q = p.copy()
            q[:3, 3] = r @ (c * p[:3, 3]) + t
            q[:3, :3] = r @ p[:3, :3]
            aligned.append(q)
        est = aligned
    ape = [np.linalg.norm(e[:3, 3] - g[:3, 3]) for g, e in zip(gt, est)]
    stats("ape", ape)
    for delta in (1.0, 10.0, 100.0):
        te, re = [], []
        for i, j in path_pairs(est, delta):
            Q = np.linalg.inv(gt[i]) @ gt[j]
            P = np.linalg.inv(est[i]) @ est[j]
            E = np.linalg.inv(Q) @ P
            te.append(np.linalg.norm(E[:3, 3]))
            re.append(np.degrees(angle(E[:3, :3])))
        stats("rpe%g.trans" % delta, te)
        stats("rpe%g.rot" % delta, re)
    dist = np.concatenate([[0.0], np.cumsum([np.linalg.norm(gt[k][:3, 3] - gt[k - 1][:3, 3]) for k in range(1, len(gt))])])
    t_errs, r_errs = [], []
    for first in range(0, len(gt), 10):
        for L in (100, 200, 300, 400, 500, 600, 700, 800):
            last = next((i for i in range(first, len(gt)) if dist[i] > dist[first] + L), -1)
            if last < 0:
                continue
            e = np.linalg.inv(np.linalg.inv(est[first]) @ est[last]) @ (np.linalg.inv(gt[first]) @ gt[last])
            t_errs.append(np.linalg.norm(e[:3, 3]) / L)
            r_errs.append(angle(e[:3, :3]) / L)
    print("drift.segments", len(t_errs))
    if t_errs:
        print("drift.translation_percent %.17g" % (100 * np.mean(t_errs)))
        print("drift.rotation_deg_per_m %.17g" % np.degrees(np.mean(r_errs)))
    print("distance %.17g" % dist[-1])
    print("end_point %.17g" % ape[-1])


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3])
