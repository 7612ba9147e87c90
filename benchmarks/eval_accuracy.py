#!/usr/bin/env python3
"""One-command accuracy report: every real slice and the rendered loops, deterministic and threaded.

The runs are the study benchmarks/studies/accuracy.yaml, executed by orbis.sweep (a local Dask
cluster by default, resumable; docs/guide/sweep.md): deterministic runs at three feature budgets
(0.9x, 1x, 1.1x the settings' own; a single deterministic run moves by several percent with any
change, so the geometric mean of the three is the figure to compare) and N threaded runs at the
settings' budget. This script only turns the sweep's rows into the report: per sequence ATE
(SE(3), every tracked frame), RPE (1 frame, translation), keyframes, map points, tracked frames,
the threaded median and spread, and the ratio to ORB-SLAM2's figure where the study gives one
(issue 18: ORB-SLAM2 built on the same machine, median of three runs). Writes WORK/results.json,
WORK/report.md and WORK/ratios.png beside the sweep's own table (WORK/results.csv, summary.md,
plots/); with --baseline OLD/results.json the table and the plot show both runs side by side.

    benchmarks/eval_accuracy.sh [--label L] [--baseline OLD/results.json] [--threaded-runs N]
                                [--workers N | --scheduler tcp://HOST:8786 | --serial] [--max-frames N]
Environment: ORBIS (the program, default build/release/orbis), ORBIS_DATA (default
../shared/datasets), WORK (the study folder, default /tmp/orbis_eval; runs resume from it).
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORK = os.environ.get("WORK", "/tmp/orbis_eval")
STUDY = os.path.join(ROOT, "benchmarks/studies/accuracy.yaml")
BUDGETS = {"det0.9": "0.9", "det1.0": "1.0", "det1.1": "1.1"}


def run_all(args):
    """The sweep's rows in this report's layout: per sequence, det runs by budget and threaded runs."""
    from orbis import sweep

    def threaded_runs(study):
        for variant in study["variants"]:
            if variant["name"] == "thr":
                variant["repeats"] = args.threaded_runs

    result = sweep.run(STUDY, WORK, scheduler=args.scheduler, workers=args.workers, serial=args.serial,
                       program=os.environ.get("ORBIS"), max_frames=args.max_frames, edit=threaded_runs)
    if result.interrupted:
        sys.exit(130)
    study, _, _ = sweep.load(STUDY, WORK, os.environ.get("ORBIS"), args.max_frames, edit=threaded_runs)
    reference = {name: seq.reference["ate"] for name, seq in study.sequences.items() if "ate" in seq.reference}
    results = {name: {"det": {}, "thr": []} for name in study.sequences}
    for row in sorted(result.rows, key=lambda r: (r["variant"], r["repeat"])):
        ok = row.get("status") == "ok"
        run = {"ate": row["ate_rmse"] if ok else float("nan"), "rpe": row.get("rpe_rmse", float("nan")) if ok else float("nan"),
               "keyframes": row.get("keyframes", 0) if ok else 0, "map_points": row.get("map_points", 0) if ok else 0,
               "tracked": row.get("frames_tracked", 0) if ok else 0, "frames": row.get("frames", 0) if ok else 0}
        run = {k: (float("nan") if v is None else v) for k, v in run.items()}
        if row["variant"] in BUDGETS:
            results[row["sequence"]]["det"][BUDGETS[row["variant"]]] = run
        else:
            results[row["sequence"]]["thr"].append(run)
    return results, reference


def gmean(values):
    values = [v for v in values if v == v]
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values and all(v > 0 for v in values) else float("nan")


def summarise(results, reference):
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
        if name in reference:
            rows[name]["ratio_thr"] = rows[name]["thr_ate_median"] / reference[name]
            rows[name]["ratio_det"] = rows[name]["det_ate_gmean"] / reference[name]
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
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, help="local Dask cluster of N workers (default: one per core)")
    where.add_argument("--scheduler", help="a running Dask scheduler, tcp://HOST:8786")
    where.add_argument("--serial", action="store_true", help="the runs one after another, no Dask")
    ap.add_argument("--max-frames", type=int, help="every run processes at most N frames (a quick look)")
    args = ap.parse_args()
    os.makedirs(WORK, exist_ok=True)
    if args.report_only:
        done = json.load(open(os.path.join(WORK, "results.json")))
        rows, args.label = done["rows"], done["label"]
    else:
        from orbis.sweep import StudyError
        try:
            results, reference = run_all(args)
        except StudyError as e:
            sys.exit(f"eval_accuracy: error: {e}")
        rows = summarise(results, reference)
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
