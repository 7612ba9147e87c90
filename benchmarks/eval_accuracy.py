#!/usr/bin/env python3
"""One-command accuracy report: every real slice and the rendered loops, deterministic and threaded.

For each sequence: deterministic runs at three feature budgets (0.9x, 1x, 1.1x the settings' own;
a single deterministic run moves by several percent with any change, so the geometric mean of the
three is the figure to compare) and N threaded runs at the settings' budget, run one at a time
(as a user runs it: the mapping thread gets the other core). Reported per sequence: ATE (SE(3),
every tracked frame), RPE (1 frame, translation), keyframes, map points, tracked frames, the
threaded median and spread, and the ratio to ORB-SLAM2's figure where there is one (issue 18:
ORB-SLAM2 built on the same machine, median of three runs). Writes WORK/results.json,
WORK/report.md and WORK/ratios.png; with --baseline OLD/results.json the table and the plot show
both runs side by side.

    benchmarks/eval_accuracy.sh [--label L] [--baseline OLD/results.json] [--threaded-runs N]
Environment: ORBIS (the program, default build/release/orbis), ORBIS_DATA (default
../shared/datasets), WORK (scratch, default /tmp/orbis_eval).
"""
import argparse
import concurrent.futures as cf
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ORBIS = os.environ.get("ORBIS", os.path.join(ROOT, "build/release/orbis"))
DATA = os.environ.get("ORBIS_DATA", os.path.join(ROOT, "../shared/datasets"))
WORK = os.environ.get("WORK", "/tmp/orbis_eval")
SETTINGS = os.path.join(ROOT, "examples/settings")

# ORB-SLAM2 on this machine (issue 18): SE(3) ATE of every tracked frame, median of three, metres.
REFERENCE = {"teddy": 6.96e-3, "euroc": 0.83e-3, "kitti06": 46.5e-3, "kitti0102": 0.702}


def synth(name, *args):
    folder = os.path.join(WORK, name)
    if not os.path.exists(os.path.join(folder, "settings.yaml")):
        subprocess.run([ORBIS, "synth", folder, "--frames", "300", "--extra", "75", "--width", "320", "--height",
                        "240", "--fx", "250", "--noise", "4", "--threads", "2", *args],
                       check=True, stdout=subprocess.DEVNULL)
    return folder


def sequences():
    d = DATA
    euroc_gt = "mav0/state_groundtruth_estimate0/data.csv"
    rgbd = synth("synth_rgbd", "--seed", "21")
    rgbd_noisy = synth("synth_rgbd_depthnoise", "--seed", "21", "--depth-noise", "0.0014")
    stereo = synth("synth_stereo", "--seed", "22", "--layout", "euroc")
    k06 = f"{d}/kitti_06_first51"
    k0102 = f"{d}/kitti_0102_first51"
    # name: (dataset kind, path, settings, ground truth, extra eval arguments)
    return {
        "teddy": ("tum", f"{d}/tum_fr3_teddy_200", f"{SETTINGS}/TUM3.yaml", f"{d}/tum_fr3_teddy_200/groundtruth.txt", []),
        "euroc": ("euroc", f"{d}/euroc_V1_01_easy_95", f"{SETTINGS}/EuRoC.yaml", f"{d}/euroc_V1_01_easy_95/{euroc_gt}", []),
        "kitti06": ("kitti", k06, f"{SETTINGS}/KITTI04-12.yaml", f"{k06}/poses/06.txt",
                    ["--gt-times", f"{k06}/sequences/06/times.txt"]),
        "kitti0102": ("kitti", k0102, f"{SETTINGS}/KITTI00-02.yaml", f"{k0102}/poses/0102.txt",
                      ["--gt-times", f"{k0102}/sequences/0102/times.txt"]),
        "rgbd_loop": ("tum", rgbd, f"{rgbd}/settings.yaml", f"{rgbd}/groundtruth.txt", []),
        "rgbd_loop_depthnoise": ("tum", rgbd_noisy, f"{rgbd_noisy}/settings.yaml", f"{rgbd_noisy}/groundtruth.txt", []),
        "stereo_loop": ("euroc", stereo, f"{stereo}/settings.yaml", f"{stereo}/{euroc_gt}", []),
    }


def budget_settings(settings, factor, out):
    text = open(settings).read()
    n = int(re.search(r"^ORBextractor.nFeatures:\s*(\d+)", text, re.M).group(1))
    n = int(round(n * factor / 10.0)) * 10
    with open(out, "w") as f:
        f.write(re.sub(r"^ORBextractor.nFeatures:.*$", f"ORBextractor.nFeatures: {n}", text, flags=re.M))
    return out


def run_one(name, seq, tag, deterministic, factor):
    kind, path, settings, gt, eval_args = seq
    out = os.path.join(WORK, f"out_{name}_{tag}")
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    cfg = budget_settings(settings, factor, os.path.join(out, "settings.yaml"))
    cmd = [ORBIS, "run", kind, path, "--settings", cfg, "--out", out] + (["--deterministic"] if deterministic else [])
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=open(os.path.join(out, "stderr.txt"), "w"))
    try:
        r = json.load(open(os.path.join(out, "report.json")))
    except (OSError, ValueError):
        return {"ate": float("nan"), "rpe": float("nan"), "keyframes": 0, "map_points": 0, "tracked": 0, "frames": 0}
    rpe = subprocess.run([ORBIS, "eval", "rpe", gt, os.path.join(out, "trajectory.txt"), "--json", *eval_args],
                         capture_output=True, text=True)
    try:
        rpe_rmse = json.loads(rpe.stdout)["rmse"]
    except ValueError:
        rpe_rmse = float("nan")
    return {"ate": r["ate"]["rmse"], "rpe": rpe_rmse, "keyframes": r["keyframes"], "map_points": r["map_points"],
            "tracked": r["frames_tracked"], "frames": r["frames"]}


def gmean(values):
    values = [v for v in values if v == v]
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values and all(v > 0 for v in values) else float("nan")


def run_all(threaded_runs):
    seqs = sequences()
    results = {name: {"det": {}, "thr": []} for name in seqs}
    # Deterministic runs are single-threaded: two at a time on two cores.
    with cf.ThreadPoolExecutor(max_workers=2) as pool:
        jobs = {pool.submit(run_one, name, seq, f"det{f}", True, f): (name, f)
                for name, seq in seqs.items() for f in (0.9, 1.0, 1.1)}
        for job in cf.as_completed(jobs):
            name, f = jobs[job]
            results[name]["det"][str(f)] = job.result()
    # Threaded runs one at a time, as a user runs them.
    for k in range(threaded_runs):
        for name, seq in seqs.items():
            results[name]["thr"].append(run_one(name, seq, f"thr{k}", False, 1.0))
    return results


def summarise(results):
    rows = {}
    for name, r in results.items():
        det = [r["det"][k] for k in sorted(r["det"])]
        thr = r["thr"]
        ates = [t["ate"] for t in thr]
        rows[name] = {
            "det_ate_gmean": gmean([d["ate"] for d in det]),
            "det_ate": [d["ate"] for d in det],
            "det_rpe_gmean": gmean([d["rpe"] for d in det]),
            "det_keyframes": det[1]["keyframes"], "det_map_points": det[1]["map_points"],
            "thr_ate_median": statistics.median(ates), "thr_ate": ates,
            "thr_spread": (max(ates) - min(ates)) / statistics.median(ates) if statistics.median(ates) > 0 else float("nan"),
            "thr_rpe_median": statistics.median([t["rpe"] for t in thr]),
            "thr_keyframes": statistics.median([t["keyframes"] for t in thr]),
            "thr_map_points": statistics.median([t["map_points"] for t in thr]),
            "tracked": f"{min(t['tracked'] for t in thr + det)}/{det[1]['frames']}",
        }
        if name in REFERENCE:
            rows[name]["ratio_thr"] = rows[name]["thr_ate_median"] / REFERENCE[name]
            rows[name]["ratio_det"] = rows[name]["det_ate_gmean"] / REFERENCE[name]
    return rows


def mm(x):
    return f"{1000 * x:.2f}" if x == x else "nan"


def table(rows, label, base=None, base_label=None):
    lines = [f"## Accuracy report [{label}]" + (f" against [{base_label}]" if base else ""), "",
             "ATE/RPE in mm (SE(3) ATE over every tracked frame; RPE: 1-frame translation RMSE). det: geometric mean of "
             "deterministic runs at 0.9/1/1.1x the feature budget; thr: median of the threaded runs (spread = (max-min)/median). "
             "ratio: threaded median / ORB-SLAM2's median (issue 18).", ""]
    head = "| sequence | det ATE | det runs | thr ATE median | thr runs | spread | det RPE | thr RPE | KF det/thr | points det/thr | tracked | ratio thr (det) |"
    if base:
        head += " before: det ATE | before: thr ATE | before: spread | before: ratio thr |"
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    for name, r in rows.items():
        ratio = f"{r['ratio_thr']:.2f} ({r['ratio_det']:.2f})" if "ratio_thr" in r else "-"
        line = (f"| {name} | {mm(r['det_ate_gmean'])} | {' / '.join(mm(a) for a in r['det_ate'])} | {mm(r['thr_ate_median'])} | "
                f"{' / '.join(mm(a) for a in r['thr_ate'])} | {100 * r['thr_spread']:.0f}% | {mm(r['det_rpe_gmean'])} | "
                f"{mm(r['thr_rpe_median'])} | {r['det_keyframes']}/{r['thr_keyframes']:.0f} | "
                f"{r['det_map_points']}/{r['thr_map_points']:.0f} | {r['tracked']} | {ratio} |")
        if base and name in base:
            b = base[name]
            bratio = f"{b['ratio_thr']:.2f}" if "ratio_thr" in b else "-"
            line += f" {mm(b['det_ate_gmean'])} | {mm(b['thr_ate_median'])} | {100 * b['thr_spread']:.0f}% | {bratio} |"
        lines.append(line)
    return "\n".join(lines)


def plot(rows, label, path, base=None, base_label=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(rows)
    fig, ax = plt.subplots(figsize=(10, 4.5))
    width = 0.2
    # Real slices against ORB-SLAM2; rendered loops (no ORB-SLAM2 figure) against the baseline.
    def ratio(r, b, key):
        if "ratio_thr" in r:
            return r["ratio_thr"] if key == "thr" else r["ratio_det"]
        if b is None:
            return float("nan")
        return r["thr_ate_median"] / b["thr_ate_median"] if key == "thr" else r["det_ate_gmean"] / b["det_ate_gmean"]
    series = []
    if base:
        series.append((f"{base_label} threaded", [ratio(base[n], None, "thr") for n in names], "#bbbbbb"))
        series.append((f"{base_label} deterministic", [ratio(base[n], None, "det") for n in names], "#dddddd"))
    series.append((f"{label} threaded", [ratio(rows[n], base.get(n) if base else None, "thr") for n in names], "#1f77b4"))
    series.append((f"{label} deterministic", [ratio(rows[n], base.get(n) if base else None, "det") for n in names], "#9ecae1"))
    for k, (title, values, colour) in enumerate(series):
        xs = [i + (k - (len(series) - 1) / 2) * width for i in range(len(names))]
        ax.bar(xs, [v if v == v else 0 for v in values], width, label=title, color=colour)
    ax.axhline(1.0, color="k", lw=0.8)
    ax.axhline(0.9, color="r", lw=0.8, ls="--", label="target 0.9x ORB-SLAM2")
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels(names, rotation=15)
    ax.set_ylabel("ATE ratio")
    ax.set_title("ATE / ORB-SLAM2 (real slices); rendered loops: / baseline run")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--label", default=subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                                                       capture_output=True, text=True).stdout.strip())
    ap.add_argument("--baseline", help="results.json of an earlier report, shown side by side")
    ap.add_argument("--threaded-runs", type=int, default=3)
    ap.add_argument("--report-only", action="store_true", help="table and plot from WORK/results.json, no runs")
    args = ap.parse_args()
    os.makedirs(WORK, exist_ok=True)
    if args.report_only:
        done = json.load(open(os.path.join(WORK, "results.json")))
        rows, args.label = done["rows"], done["label"]
    else:
        results = run_all(args.threaded_runs)
        rows = summarise(results)
        json.dump({"label": args.label, "rows": rows, "runs": results}, open(os.path.join(WORK, "results.json"), "w"), indent=1)
    base = base_label = None
    if args.baseline:
        b = json.load(open(args.baseline))
        base, base_label = b["rows"], b["label"]
    text = table(rows, args.label, base, base_label)
    open(os.path.join(WORK, "report.md"), "w").write(text + "\n")
    print(text)
    plot(rows, args.label, os.path.join(WORK, "ratios.png"), base, base_label)
    print(f"\n{WORK}/report.md, {WORK}/ratios.png, {WORK}/results.json")


if __name__ == "__main__":
    sys.exit(main())
