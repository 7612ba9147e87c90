"""orbis._sweep_report — a study's results: the run table, the per-sequence summary and the plots.

Contract: write_results() takes every run's row (from orbis._sweep_run) and writes, into the study
folder, results.csv (one row per run, every metric; results.parquet too when pyarrow imports),
summary.csv and summary.md (per sequence and variant: runs, failures, ATE median, min, max and
spread = (max - min) / median over the repeats, RPE, keyframes, map points, tracked frames,
loops, the tracking time per frame, and the ratio to a baseline study's ATE median and to the sequence's
reference figure) and, when matplotlib imports, plots/ate.png, plots/timing.png and
plots/spread.png. Pure Python (csv): no pandas needed.
"""

from __future__ import annotations

import csv
import math
import statistics
from pathlib import Path
from typing import Any

FIRST_COLUMNS = ["id", "sequence", "variant", "repeat", "seed", "deterministic", "status", "error", "ate_rmse",
                 "rpe_rmse", "frames", "frames_tracked", "frames_lost", "keyframes", "map_points", "loops", "maps",
                 "merges", "relocalisations", "ate_matched", "run_seconds", "wall_seconds"]
SUMMARY_COLUMNS = ["sequence", "variant", "runs", "failed", "ate_median", "ate_min", "ate_max", "ate_spread",
                   "rpe_median", "keyframes_median", "map_points_median", "tracked_min", "frames", "loops_median",
                   "track_ms_median", "wall_seconds_median", "baseline_ate_median", "ratio_baseline",
                   "reference_ate", "ratio_reference"]
# The per-frame tracking cost the summary shows: report.json's whole tracking stage (ORB
# extraction included), median over the frames.
TRACK_STAGE = "median_ms.tracking: total"


def _number(v: Any) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return math.nan
    return f


def _finite(values) -> list[float]:
    return [v for v in (_number(x) for x in values) if v == v]


def _median(values) -> float:
    values = _finite(values)
    return statistics.median(values) if values else math.nan


def table_columns(rows: list[dict]) -> list[str]:
    extra = sorted({k for r in rows for k in r} - set(FIRST_COLUMNS) - {"overrides", "command", "hash", "resumed",
                                                                          "pid", "host"})
    overrides = sorted({f"set.{k}" for r in rows for k in (r.get("overrides") or {})})
    present = [c for c in FIRST_COLUMNS if any(c in r for r in rows) or c in FIRST_COLUMNS[:10]]
    return present + overrides + [c for c in extra if c not in overrides] + ["host", "hash"]


def flat(row: dict) -> dict:
    out = {k: v for k, v in row.items() if k not in ("overrides", "command")}
    for k, v in (row.get("overrides") or {}).items():
        out[f"set.{k}"] = v
    return out


def write_table(rows: list[dict], folder: Path) -> list[Path]:
    rows = sorted(rows, key=lambda r: r["id"])
    columns = table_columns(rows)
    path = folder / "results.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(flat(r))
    written = [path]
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        return written
    records = [{c: flat(r).get(c) for c in columns} for r in rows]
    for rec in records:  # one type per column: text where a column mixes
        for c in columns:
            if c.startswith("set.") and rec[c] is not None:
                rec[c] = str(rec[c])
    pyarrow.parquet.write_table(pyarrow.Table.from_pylist(records), folder / "results.parquet")
    return written + [folder / "results.parquet"]


def read_summary(path: Path) -> dict[tuple[str, str], dict]:
    """A baseline: an earlier study's folder or its summary.csv."""
    path = Path(path)
    if path.is_dir():
        path = path / "summary.csv"
    with open(path, newline="") as f:
        return {(r["sequence"], r["variant"]): r for r in csv.DictReader(f)}


def summarise(rows: list[dict], references: dict[str, dict[str, float]],
              baseline: dict[tuple[str, str], dict] | None = None) -> list[dict]:
    groups: dict[tuple[str, str], list[dict]] = {}
    order = {name: i for i, name in enumerate(references)}  # the study's order of sequences
    for r in sorted(rows, key=lambda r: (order.get(r["sequence"], len(order)), r["sequence"], r["repeat"])):
        groups.setdefault((r["sequence"], r["variant"]), []).append(r)
    summary = []
    for (seq, variant), group in groups.items():
        ok = [r for r in group if r.get("status") == "ok"]
        ates = _finite(r.get("ate_rmse") for r in ok)
        median = statistics.median(ates) if ates else math.nan
        track = _finite(r.get(TRACK_STAGE) for r in ok)
        s = {"sequence": seq, "variant": variant, "runs": len(group), "failed": len(group) - len(ok),
             "ate_median": median, "ate_min": min(ates, default=math.nan), "ate_max": max(ates, default=math.nan),
             "ate_spread": (max(ates) - min(ates)) / median if ates and median > 0 else math.nan,
             "rpe_median": _median(r.get("rpe_rmse") for r in ok),
             "keyframes_median": _median(r.get("keyframes") for r in ok),
             "map_points_median": _median(r.get("map_points") for r in ok),
             "tracked_min": min(_finite(r.get("frames_tracked") for r in ok), default=math.nan),
             "frames": max(_finite(r.get("frames") for r in ok), default=math.nan),
             "loops_median": _median(r.get("loops") for r in ok),
             "track_ms_median": _median(track),
             "wall_seconds_median": _median(r.get("wall_seconds") for r in ok)}
        base = (baseline or {}).get((seq, variant))
        s["baseline_ate_median"] = _number(base["ate_median"]) if base else math.nan
        s["ratio_baseline"] = median / s["baseline_ate_median"] if base and s["baseline_ate_median"] > 0 else math.nan
        ref = references.get(seq, {}).get("ate")
        s["reference_ate"] = ref if ref is not None else math.nan
        s["ratio_reference"] = median / ref if ref else math.nan
        summary.append(s)
    return summary


def _fmt(v: Any, column: str) -> str:
    f = _number(v)
    if isinstance(v, str) and f != f:
        return v
    if f != f:
        return "-"
    if column.endswith("spread"):
        return f"{100 * f:.0f}%"
    if column.startswith(("ate", "rpe", "baseline_ate", "reference_ate")):
        return f"{1000 * f:.2f}"
    if column.startswith(("ratio", "track_ms", "wall")):
        return f"{f:.2f}"
    return f"{f:.0f}"


def write_summary(summary: list[dict], folder: Path, reference_label: str) -> str:
    with open(folder / "summary.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=SUMMARY_COLUMNS)
        w.writeheader()
        w.writerows(summary)
    shown = [c for c in SUMMARY_COLUMNS if any(_number(s.get(c)) == _number(s.get(c)) for s in summary)
             or c in ("sequence", "variant")]
    lines = [f"ATE and RPE in mm; spread = (max - min) / median over the repeats; ratio_reference = ATE median / "
             f"{reference_label}; ratio_baseline = ATE median / the baseline study's.", "",
             "| " + " | ".join(shown) + " |", "|" + "---|" * len(shown)]
    for s in summary:
        lines.append("| " + " | ".join(_fmt(s.get(c), c) for c in shown) + " |")
    text = "\n".join(lines) + "\n"
    (folder / "summary.md").write_text(text)
    return text


def write_plots(rows: list[dict], summary: list[dict], folder: Path, title: str) -> list[Path]:
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return []
    plots = folder / "plots"
    plots.mkdir(exist_ok=True)
    sequences = list(dict.fromkeys(s["sequence"] for s in summary))
    variants = list(dict.fromkeys(s["variant"] for s in summary))
    by_key = {(s["sequence"], s["variant"]): s for s in summary}
    written = []

    def grouped(path: Path, value, ylabel: str, heading: str, errors=None, log_when_wide: bool = False) -> None:
        fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(sequences) + 2), 4.5))
        width = 0.8 / max(1, len(variants))
        for k, v in enumerate(variants):
            xs = [i + (k - (len(variants) - 1) / 2) * width for i in range(len(sequences))]
            ys = [value(by_key.get((seq, v), {})) for seq in sequences]
            err = None
            if errors:
                lo_hi = [errors(by_key.get((seq, v), {}), y) for seq, y in zip(sequences, ys)]
                err = [[max(0.0, e[0]) for e in lo_hi], [max(0.0, e[1]) for e in lo_hi]]
            ax.bar(xs, [y if y == y else 0 for y in ys], width, yerr=err, capsize=2, label=v)
        shown = [y for v in variants for y in (value(by_key.get((seq, v), {})) for seq in sequences) if y == y and y > 0]
        if log_when_wide and shown and max(shown) > 30 * min(shown):  # sequences of very different scales
            ax.set_yscale("log")
        ax.set_xticks(range(len(sequences)))
        ax.set_xticklabels(sequences, rotation=15)
        ax.set_ylabel(ylabel)
        ax.set_title(heading)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)

    grouped(plots / "ate.png", lambda s: 1000 * _number(s.get("ate_median")), "ATE RMSE, mm (median; bars: min-max)",
            f"{title}: trajectory error per sequence and variant",
            errors=lambda s, y: (y - 1000 * _number(s.get("ate_min")) if s else 0,
                                 1000 * _number(s.get("ate_max")) - y if s else 0), log_when_wide=True)
    grouped(plots / "timing.png", lambda s: _number(s.get("track_ms_median")), "tracking ms per frame (median)",
            f"{title}: tracking time per frame (ORB extraction included)")
    grouped(plots / "spread.png", lambda s: 100 * _number(s.get("ate_spread")), "(max - min) / median, %",
            f"{title}: ATE spread over the repeats")
    for path in written:
        if not path.exists():
            written.remove(path)
    return written
