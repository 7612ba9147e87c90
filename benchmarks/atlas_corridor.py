#!/usr/bin/env python3
"""The atlas against ORB-SLAM2's single map on rendered corridor loops with a blackout (issue 32).

For each seed and blackout START:COUNT it renders the corridor loop (`orbis synth --scene corridor
--black START:COUNT`: black frames while the camera moves on into ground the map has not seen),
then runs RGB-D, stereo and monocular, --deterministic, with the atlas and with --single-map, and
prints one row per run: frames tracked after the blackout, ATE over every tracked frame (SE(3);
Sim(3) for monocular), maps opened, the frame the new map started on and the frame of the merge,
the seam error: the relative pose between the frames of the two keyframes the merge matched (one
per map) against the ground truth (translation error, mm; monocular in ground-truth units at the
run's scale), and the gap error: the same across the blackout (the last frame of the first map and
the first of the next), which only the rest of the loop ties together; "+after": frames from the
end of the blackout to the merge. Pure Python (no NumPy); the JSON of every row goes
to WORK/atlas_corridor.json.

  benchmarks/atlas_corridor.py [--orbis BIN] [--work DIR] [--seeds 1,2] [--blackouts 100:30,200:30]
                               [--sensors rgbd,stereo,mono] [--reuse] [--markdown]
"""
import argparse
import json
import math
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FPS = 30.0
START_TIME = 1.0  # orbis synth: the timestamp of frame 0


def frame_of(t):
    return round((t - START_TIME) * FPS)


def quat_to_matrix(qx, qy, qz, qw):
    return [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]


def relative_translation(a, b):
    """Translation of pose b seen from pose a: R_a^T (t_b - t_a)."""
    (Ra, ta), (_, tb) = a, b
    d = [tb[i] - ta[i] for i in range(3)]
    return [sum(Ra[r][c] * d[r] for r in range(3)) for c in range(3)]


def read_tum(path):
    poses = {}
    for line in open(path):
        if line.startswith('#') or not line.strip():
            continue
        v = [float(x) for x in line.split()]
        poses[frame_of(v[0])] = (quat_to_matrix(*v[4:8]), v[1:4])
    return poses


def read_euroc_gt(path):
    poses = {}
    for line in open(path):
        if line.startswith('#') or not line.strip():
            continue
        v = [float(x) for x in line.split(',')]
        t = v[0] * 1e-9
        poses[frame_of(t)] = (quat_to_matrix(v[5], v[6], v[7], v[4]), v[1:4])
    return poses


def read_maps(path):
    maps = {}
    for line in open(path):
        if line.startswith('#') or not line.strip():
            continue
        t, tracked_in, _ = line.split()
        maps[frame_of(float(t))] = int(tracked_in)
    return maps


def render(orbis, work, seed, black, layout):
    folder = os.path.join(work, f"corridor_{layout}_s{seed}_b{black.replace(':', '_')}")
    if not os.path.exists(os.path.join(folder, "settings.yaml")):
        subprocess.run([orbis, "synth", folder, "--scene", "corridor", "--frames", "300", "--extra", "75",
                        "--width", "320", "--height", "240", "--fx", "250", "--noise", "4", "--threads", "2",
                        "--black", black, "--seed", str(seed), "--layout", layout],
                       check=True, stdout=subprocess.DEVNULL)
    return folder


def run(orbis, work, seq, kind, sensor, single, tag, reuse):
    out = os.path.join(work, tag)
    if reuse and os.path.exists(os.path.join(out, "report.json")):
        return out
    settings = os.path.join(seq, "settings_mono.yaml" if sensor == "mono" else "settings.yaml")
    cmd = [orbis, "run", kind, seq, "--settings", settings, "--deterministic", "--out", out]
    if sensor == "mono":
        cmd += ["--sensor", "mono"]
    if single:
        cmd.append("--single-map")
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=open(out + ".stderr", "w"))
    return out


def score(out, gt, start, count, sensor):
    report = json.load(open(os.path.join(out, "report.json")))
    est = read_tum(os.path.join(out, "trajectory.txt"))
    maps = read_maps(os.path.join(out, "trajectory_maps.txt"))
    end = start + count
    frames = report["frames"]
    row = {
        "tracked": report["frames_tracked"], "frames": frames,
        "tracked_after_blackout": sum(1 for i in est if i >= end), "frames_after_blackout": frames - end,
        "ate_mm": 1000 * report["ate"]["rmse"] if report.get("ate") else None,
        "maps": len(report.get("maps", [])) or 1,
        "new_map_frame": None, "merge_frame": None, "merge_inliers": None, "merge_ms": None, "seam_error_mm": None,
        "gap_error_mm": None, "frames_to_merge": None,
    }
    if len(report.get("maps", [])) > 1:
        row["new_map_frame"] = report["maps"][1]["start_frame"]
    if report.get("merges"):
        m = report["merges"][0]
        row.update(merge_frame=m["frame"], merge_inliers=m["inliers"], merge_ms=round(m["ms"], 1),
                   frames_to_merge=m["frame"] - end)
    # The seam: the frames of the two keyframes the merge matched (one per map), and across the
    # blackout: the last frame of the first map and the first of the next (nothing ties them but
    # the rest of the loop).
    scale = 1.0
    if sensor == "mono":  # the map's unit: estimated over true distance along the whole run
        keys = sorted(i for i in est if i in gt)
        dist = lambda p: sum(math.dist(p[keys[j]][1], p[keys[j + 1]][1]) for j in range(len(keys) - 1))
        scale = dist(gt) / max(dist(est), 1e-9)

    def relative_error(a, b):
        e, g = relative_translation(est[a], est[b]), relative_translation(gt[a], gt[b])
        return 1000 * math.dist([scale * x for x in e], g)

    if report.get("merges"):
        m = report["merges"][0]
        if m["frame"] in est and m["other_frame"] in est:
            row["seam_error_mm"] = relative_error(m["other_frame"], m["frame"])
            row["seam_frames"] = (m["other_frame"], m["frame"])
    before = [i for i in est if i < start and maps.get(i) == 0]
    after = sorted(i for i in est if i >= end and maps.get(i, 0) != 0)
    if before and after and report.get("merges"):
        row["gap_error_mm"] = relative_error(max(before), after[0])
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--orbis", default=os.path.join(ROOT, "build/release/orbis"))
    ap.add_argument("--work", default="/tmp/orbis_atlas_corridor")
    ap.add_argument("--seeds", default="1,2")
    ap.add_argument("--blackouts", default="100:30,200:30")
    ap.add_argument("--sensors", default="rgbd,stereo,mono")
    ap.add_argument("--reuse", action="store_true", help="score existing runs in WORK instead of running again")
    ap.add_argument("--markdown", action="store_true", help="also print the rows as a Markdown table")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    rows = []
    print(f"{'sensor':7} {'seed':>4} {'blackout':>9} {'mode':7} {'after':>9} {'ATE mm':>8} {'maps':>4} "
          f"{'new map':>7} {'merge':>5} {'+after':>6} {'inl':>4} {'seam mm':>8} {'gap mm':>8}")
    for seed in args.seeds.split(","):
        for black in args.blackouts.split(","):
            start, count = (int(x) for x in black.split(":"))
            for sensor in args.sensors.split(","):
                layout = "euroc" if sensor == "stereo" else "tum"
                seq = render(args.orbis, args.work, seed, black, layout)
                gt = (read_euroc_gt(os.path.join(seq, "mav0/state_groundtruth_estimate0/data.csv"))
                      if layout == "euroc" else read_tum(os.path.join(seq, "groundtruth.txt")))
                for single in (False, True):
                    mode = "single" if single else "atlas"
                    tag = f"out_{sensor}_s{seed}_b{start}_{count}_{mode}"
                    out = run(args.orbis, args.work, seq, layout, sensor, single, tag, args.reuse)
                    try:
                        row = score(out, gt, start, count, sensor)
                    except (OSError, ValueError, KeyError) as e:
                        row = {"error": str(e)}
                    row.update(sensor=sensor, seed=int(seed), blackout=black, mode=mode)
                    rows.append(row)
                    fmt = lambda v, f: "-" if v is None else format(v, f)
                    if "error" in row:
                        print(f"{sensor:7} {seed:>4} {black:>9} {mode:7} error: {row['error']}")
                    else:
                        print(f"{sensor:7} {seed:>4} {black:>9} {mode:7} "
                              f"{row['tracked_after_blackout']:>4}/{row['frames_after_blackout']:<4} "
                              f"{fmt(row['ate_mm'], '8.1f')} {row['maps']:>4} {fmt(row['new_map_frame'], '>7')} "
                              f"{fmt(row['merge_frame'], '>5')} {fmt(row['frames_to_merge'], '>6')} "
                              f"{fmt(row['merge_inliers'], '>4')} "
                              f"{fmt(row['seam_error_mm'], '8.1f')} {fmt(row['gap_error_mm'], '8.1f')}", flush=True)
    json.dump(rows, open(os.path.join(args.work, "atlas_corridor.json"), "w"), indent=1)
    if args.markdown:
        print_markdown(rows)


def print_markdown(rows):
    cell = lambda v, f="": "–" if v is None else format(v, f)
    print("\n| sensor | seed | blackout | mode | after | ATE mm | maps | new map at | merge at | +after "
          "| inliers | seam mm | gap mm |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if "error" in r:
            print(f"| {r['sensor']} | {r['seed']} | {r['blackout']} | {r['mode']} | error: {r['error']} |||||||||")
            continue
        print(f"| {r['sensor']} | {r['seed']} | {r['blackout']} | {r['mode']} | "
              f"{r['tracked_after_blackout']}/{r['frames_after_blackout']} | {cell(r['ate_mm'], '.1f')} | {r['maps']} | "
              f"{cell(r['new_map_frame'])} | {cell(r['merge_frame'])} | {cell(r['frames_to_merge'])} | "
              f"{cell(r['merge_inliers'])} | {cell(r['seam_error_mm'], '.1f')} | {cell(r['gap_error_mm'], '.1f')} |")


if __name__ == "__main__":
    main()
