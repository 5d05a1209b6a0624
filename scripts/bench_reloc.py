#!/usr/bin/env python3
"""Relocalisation benchmark (issue 18), simulated; not a CI test.

Per world: one mapping drive (adit sim + adit replay --save-bundle), then short drives from rest at random
places and headings along the mapped roadway (and, where the route leaves the map, outside it), each replayed
with --prior-map. A drive is judged at its first fix (the first pose in map_trajectory.tum):
  success  the pose is within 0.3 m / 2 deg of the truth;
  wrong    a fix that is not a success (accepted but wrong; target 0);
  none     no fix before the drive ends (inside the map: a miss; outside it: the right answer, a refusal).
The truth is expressed in the map frame through the mapping drive's own estimate at the nearest mapped place
(its ground truth times its estimate^-1 there): what is judged is where the run is in the map, not the map's
own drift. Time to first fix: sensor time from the first sweep, and the relocaliser's wall time until then.
Inside = the drive starts within 3 m of the mapped path; outside = every pose of the drive is > 40 m from it.

  scripts/bench_reloc.py [--worlds W ...] [--drives 50] [--outside 10] [--duration 20] [--map-duration 200] [--jobs 2]
                         [--keep-map] [--judge-only] [--start-pose-error M DEG]
With --start-pose-error each drive is told its start pose (adit replay --start-pose), off by up to M metres and
DEG degrees: the operator's guess, which lets a self-similar map (room-and-pillar) fix near it.
Needs a build (build/bin/adit) and numpy (Debian python3-numpy: run with /usr/bin/python3). Keeps its runs in
logs/bench-reloc/ and prints a Markdown table.
"""
import argparse, json, math, os, random, shutil, subprocess, sys
from concurrent.futures import ThreadPoolExecutor
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ADIT = os.environ.get("ADIT_BIN", os.path.join(ROOT, "build", "bin", "adit"))  # another build: ADIT_BIN
OUT = os.path.join(ROOT, "logs", "bench-reloc")


def run(args):
    subprocess.run(["nice", "-n", "10", ADIT] + args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def quat_to_matrix(qx, qy, qz, qw):
    x, y, z, w = qx, qy, qz, qw
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def read_tum(path):
    poses = {}
    if not os.path.exists(path):
        return poses
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        T = np.eye(4)
        T[:3, :3] = quat_to_matrix(*v[4:8])
        T[:3, 3] = v[1:4]
        poses[round(v[0] * 1e6)] = T
    return poses


def angle_deg(R):
    return math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2))))


def map_world(world, duration, seed, build=True):
    d = os.path.join(OUT, world)
    os.makedirs(d, exist_ok=True)
    log, gt = os.path.join(d, "map.lcmlog"), os.path.join(d, "map_gt.tum")
    if build:
        run(["sim", "--world", world, "--duration", str(duration), "--seed", str(seed), "-o", log, "--gt", gt])
        run(["replay", log, "-o", os.path.join(d, "map_run"), "--save-bundle", os.path.join(d, "bundle"),
             "--no-progress", "--record", "^$"])
        os.remove(log)
    truth, est = read_tum(gt), read_tum(os.path.join(d, "map_run", "trajectory.tum"))
    keys = sorted(k for k in truth if k in est)
    positions = np.array([truth[k][:3, 3] for k in keys])
    # Per mapped pose: T_world_map there (the map's local frame against the world).
    anchors = [truth[k] @ np.linalg.inv(est[k]) for k in keys]
    route = int(subprocess.run([ADIT, "sim", "--world", world, "--duration", "1", "-o", os.devnull],
                               capture_output=True, text=True).stdout.split("(")[1].split(" m route")[0])
    return {"dir": d, "positions": positions, "anchors": anchors, "route_m": route}


def start_pose_args(m, truth_start, rng, error):
    """--start-pose: the drive's true start in the map frame, off by up to error = (metres, degrees)."""
    nearest = int(np.argmin(np.linalg.norm(m["positions"] - truth_start[:3, 3], axis=1)))
    T = np.linalg.inv(m["anchors"][nearest]) @ truth_start
    angle = rng.uniform(0, 2 * math.pi)
    dist = rng.uniform(0, error[0])
    x, y, z = T[0, 3] + dist * math.cos(angle), T[1, 3] + dist * math.sin(angle), T[2, 3]
    heading = math.degrees(math.atan2(T[1, 0], T[0, 0])) + rng.uniform(-error[1], error[1])
    return ["--start-pose", f"{x:.3f}", f"{y:.3f}", f"{z:.3f}", f"{heading:.2f}"]


def short_drive(world, m, seed, index, start, reverse, duration, configs=(), start_error=None):
    d = os.path.join(m["dir"], f"drive{index:03d}")
    os.makedirs(d, exist_ok=True)
    log, gt = os.path.join(d, "in.lcmlog"), os.path.join(d, "gt.tum")
    args = ["sim", "--world", world, "--duration", str(duration), "--seed", str(seed), "--start-distance", f"{start:.1f}",
            "-o", log, "--gt", gt]
    run(args + (["--reverse"] if reverse else []))
    hint = []
    if start_error:
        truth = read_tum(gt)
        hint = start_pose_args(m, truth[min(truth)], random.Random(seed * 1000 + index), start_error)
    run(["replay", log, "-o", os.path.join(d, "run"), "--prior-map", os.path.join(m["dir"], "bundle"), "--no-progress",
         "--record", "^$"] + (["--config"] + list(configs) if configs else []) + hint)
    os.remove(log)
    return judge(m, d, index, start, reverse)


def judge(m, d, index, start, reverse):
    gt = os.path.join(d, "gt.tum")
    truth = read_tum(gt)
    fix = read_tum(os.path.join(d, "run", "map_trajectory.tum"))
    summary = json.load(open(os.path.join(d, "run", "relocalisation.json")))
    start_pos = truth[min(truth)][:3, 3]
    gaps = [np.min(np.linalg.norm(m["positions"] - truth[k][:3, 3], axis=1)) for k in sorted(truth)]
    where = "inside" if gaps[0] < 3.0 else ("outside" if min(gaps) > 40.0 else "edge")
    out = {"index": index, "start": start, "reverse": reverse, "where": where, "fixed": bool(fix),
           "fix_s": summary["first_fix_sensor_s"], "compute_ms": summary["first_fix_compute_ms"]}
    if fix:
        t = min(fix)
        nearest = int(np.argmin(np.linalg.norm(m["positions"] - truth[t][:3, 3], axis=1)))
        E = np.linalg.inv(truth[t]) @ m["anchors"][nearest] @ fix[t]
        out["error_m"], out["error_deg"] = float(np.linalg.norm(E[:3, 3])), angle_deg(E[:3, :3])
        out["success"] = out["error_m"] <= 0.3 and out["error_deg"] <= 2.0
    return out


def starts(rng, m, n_inside, n_outside, mapped_m):
    route = m["route_m"]
    chosen = []
    for _ in range(n_inside):
        s = rng.uniform(5.0, mapped_m - 15.0)
        reverse = rng.random() < 0.5
        chosen.append((route - s if reverse else s, reverse))
    for _ in range(n_outside):  # beyond the mapped part of the route, well clear of its ends
        s = rng.uniform(mapped_m + 60.0, route - 60.0)
        reverse = rng.random() < 0.5
        chosen.append((route - s if reverse else s, reverse))
    return chosen


def table(world, results):
    rows = []
    for where in ("inside", "outside"):
        r = [x for x in results if x["where"] == where]
        if not r:
            continue
        fixed = [x for x in r if x["fixed"]]
        ok = [x for x in fixed if x["success"]]
        wrong = [x for x in fixed if not x["success"]]
        fix_s = sorted(x["fix_s"] for x in fixed)
        comp = sorted(x["compute_ms"] for x in fixed)
        med = lambda v: v[len(v) // 2] if v else float("nan")
        within2 = sum(1 for x in ok if x["fix_s"] <= 2.0)
        rows.append(f"| {world} | {where} | {len(r)} | {len(ok)} ({100.0 * len(ok) / len(r):.0f} %) | {within2} | "
                    f"{len(wrong)} | {len(r) - len(fixed)} | {med(fix_s):.1f} / {fix_s[-1] if fix_s else float('nan'):.1f} | "
                    f"{med(comp):.0f} |")
    return rows


def judge_only(a):
    lines = []
    for world in a.worlds:
        m = map_world(world, 0, a.seed, build=False)
        results = []
        for name in sorted(os.listdir(m["dir"])):
            d = os.path.join(m["dir"], name)
            if name.startswith("drive") and os.path.exists(os.path.join(d, "run", "relocalisation.json")):
                results.append(judge(m, d, int(name[5:]), float("nan"), None))
        lines += table(world, results)
    print("\n".join(lines))


def main():
    global OUT
    p = argparse.ArgumentParser()
    p.add_argument("--worlds", nargs="+", default=["roadway-loop", "room-and-pillar"])
    p.add_argument("--drives", type=int, default=50)
    p.add_argument("--outside", type=int, default=10)
    p.add_argument("--duration", type=float, default=20.0)
    p.add_argument("--map-duration", type=float, default=200.0)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--judge-only", action="store_true", help="judge the drives already in logs/bench-reloc again")
    p.add_argument("--keep-map", action="store_true", help="reuse the mapping drives already in logs/bench-reloc")
    p.add_argument("--out", default=None, help="folder of the runs (default logs/bench-reloc)")
    p.add_argument("--config", nargs="+", default=[], help="configuration files for the short drives' replays")
    p.add_argument("--start-pose-error", nargs=2, type=float, default=None, metavar=("M", "DEG"),
                   help="give each drive its start pose (--start-pose), off by up to M metres and DEG degrees")
    a = p.parse_args()
    OUT = os.path.abspath(a.out) if a.out else OUT
    if a.judge_only:
        return judge_only(a)
    for world in a.worlds:
        if a.keep_map:
            for name in os.listdir(os.path.join(OUT, world)):
                if name.startswith("drive"):
                    shutil.rmtree(os.path.join(OUT, world, name))
        else:
            shutil.rmtree(os.path.join(OUT, world), ignore_errors=True)
    lines = ["| world | starts | drives | success (0.3 m / 2 deg) | of them fixed within 2 s | wrong | no fix | "
             "time to first fix, sensor s (median / max) | compute ms (median) |", "|---|---|---|---|---|---|---|---|---|"]
    for world in a.worlds:
        m = map_world(world, a.map_duration, a.seed, build=not a.keep_map)
        mapped = float(np.sum(np.linalg.norm(np.diff(m["positions"], axis=0), axis=1)))
        rng = random.Random(a.seed)
        outside = a.outside if m["route_m"] > mapped + 180.0 and world == "roadway-loop" else 0
        plan = starts(rng, m, a.drives, outside, mapped)
        with ThreadPoolExecutor(a.jobs) as pool:
            results = list(pool.map(lambda ia: short_drive(world, m, a.seed, ia[0], ia[1][0], ia[1][1], a.duration,
                                                                [os.path.abspath(c) for c in a.config],
                                                                a.start_pose_error),
                                    enumerate(plan)))
        json.dump(results, open(os.path.join(m["dir"], "results.json"), "w"), indent=1)
        print(f"{world}: mapped {mapped:.0f} m of a {m['route_m']} m route; {len(results)} drives", file=sys.stderr)
        lines += table(world, results)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
