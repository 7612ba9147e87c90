"""orbis._sweep_run — one run of a study: its command, its input hash, and its execution.

Contract: plan() turns a study Run into a plain dict (picklable, so a Dask worker on another
machine can take it): the `orbis run` command, the run's settings file text (the sequence's file
with the variant's overrides), the ground truth for RPE, and a SHA-256 of all of these — the
run's identity. execute(plan) runs it in a fresh attempt folder beside the run's folder and, when
it ends, swaps the attempt in whole, so a run folder only ever holds one finished attempt:
run.json (status ok/failed, the hash, the metrics or the error), report.json, trajectory.txt,
stderr.txt. A run whose run.json says ok with the same hash is finished (finished_row) and is not
run again. The orbis process dies with the worker that started it (PR_SET_PDEATHSIG), so a
killed worker leaves no run behind writing into the study; it runs in a session of its own, so a
Ctrl-C typed at the study's terminal stops the study (which stops its workers) rather than
failing the runs under way one by one.
"""

from __future__ import annotations

import ctypes
import hashlib
import json
import math
import os
import re
import shutil
import signal
import socket
import subprocess
import time
import uuid
from pathlib import Path
from typing import Any

try:
    _prctl = ctypes.CDLL(None, use_errno=True).prctl
except (OSError, AttributeError):  # not Linux: runs then outlive a killed worker
    _prctl = None
_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    if _prctl is not None:
        _prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)


def derive_settings(text: str, overrides: dict[str, Any], budget: float | None, source: str) -> str:
    """The settings file with each override's line replaced (or appended) and the budget applied."""
    if budget is not None:
        m = re.search(r"^ORBextractor\.nFeatures:\s*(\d+)", text, re.M)
        if not m:
            raise ValueError(f"{source}: has no ORBextractor.nFeatures to scale by the budget factor")
        # Rounded to tens, as benchmarks/eval_accuracy.py always did.
        overrides = {"ORBextractor.nFeatures": int(round(int(m.group(1)) * budget / 10.0)) * 10, **overrides}
    for key, value in overrides.items():
        line = f"{key}: {json.dumps(value)}"
        # A key's entry is its line plus any indented continuation lines (a matrix block).
        pattern = re.compile(rf"^{re.escape(key)}:.*(?:\n[ \t]+.*)*", re.M)
        text, found = pattern.subn(lambda _: line, text, count=1)
        if not found:
            text = text.rstrip("\n") + "\n" + line + "\n"
    return text


def plan(run, program: str, study_out: Path) -> dict:
    """A picklable description of one run, with the hash of its inputs."""
    seq = run.sequence
    command = ["run", seq.dataset, str(seq.path)]
    settings_text = None
    if seq.settings is not None:
        # A sequence still to be rendered has no settings file yet (only --dry-run plans it then).
        settings_text = seq.settings.read_text() if seq.settings.exists() else None
        if settings_text is not None and (run.overrides or run.budget is not None):
            settings_text = derive_settings(settings_text, run.overrides, run.budget, str(seq.settings))
        command += ["--settings", "{folder}/settings.yaml"]
    o = run.options
    if o.get("sensor"):
        command += ["--sensor", o["sensor"]]
    if seq.kitti_sequence:
        command += ["--sequence", seq.kitti_sequence]
    if o.get("max_frames"):
        command += ["--max-frames", str(o["max_frames"])]
    if o.get("vocab"):
        command += ["--vocab", o["vocab"]]
    for flag, on in (("--deterministic", o["deterministic"]), ("--no-loop", not o["loop"]),
                     ("--realtime", o.get("realtime"))):
        if on:
            command.append(flag)
    rpe = None
    if seq.ground_truth is not None:
        rpe = ["eval", "rpe", str(seq.ground_truth), "{folder}/trajectory.txt", "--json"]
        if seq.gt_times is not None:
            rpe += ["--gt-times", str(seq.gt_times)]
    identity = json.dumps({"command": command, "settings": settings_text, "rpe": rpe}, sort_keys=True)
    return {"id": run.id, "sequence": seq.name, "variant": run.variant, "repeat": run.repeat,
            "seed": run.overrides.get("System.seed"), "deterministic": o["deterministic"],
            "overrides": {**run.overrides, **({"budget": run.budget} if run.budget is not None else {})},
            "program": program, "folder": str(study_out / "runs" / run.id), "command": command,
            "settings_text": settings_text, "rpe": rpe,
            "hash": hashlib.sha256(identity.encode()).hexdigest()}


def finished_row(p: dict) -> dict | None:
    """The recorded row of a finished run with the same inputs, or None."""
    try:
        record = json.loads((Path(p["folder"]) / "run.json").read_text())
    except (OSError, ValueError):
        return None
    if record.get("status") != "ok" or record.get("hash") != p["hash"]:
        return None
    if not (Path(p["folder"]) / "report.json").is_file():
        return None
    return {**record, "resumed": True}


def _fill(args: list[str], folder: Path) -> list[str]:
    return [a.replace("{folder}", str(folder)) for a in args]


def _tail(path: Path, lines: int = 6) -> str:
    try:
        text = path.read_text(errors="replace").strip().splitlines()
    except OSError:
        return ""
    # Progress bars redraw with carriage returns: keep what a terminal would show last.
    return " | ".join(t.split("\r")[-1].strip() for t in text[-lines:] if t.strip())


def metrics_of(report: dict) -> dict:
    """The table's columns from one report.json."""
    ate = report.get("ate") or {}
    row = {"ate_rmse": ate.get("rmse", math.nan), "ate_matched": ate.get("matched"),
           "frames": report.get("frames"), "frames_tracked": report.get("frames_tracked"),
           "frames_lost": report.get("frames_lost"), "keyframes": report.get("keyframes"),
           "map_points": report.get("map_points"), "loops": len(report.get("loops") or []),
           "relocalisations": report.get("relocalisations"), "run_seconds": report.get("seconds")}
    # Several maps and their merges, when the report has them (the atlas).
    for key in ("maps", "merges"):
        if key in report:
            value = report[key]
            row[key] = len(value) if isinstance(value, list) else value
    for stage, t in (report.get("timing_ms") or {}).items():
        row[f"median_ms.{stage}"] = t.get("median")
    return row


def execute(p: dict) -> dict:
    """Runs one planned run (a Dask task, or called directly); returns its row, never raises."""
    folder = Path(p["folder"])
    done = finished_row(p)
    if done:
        return done
    folder.parent.mkdir(parents=True, exist_ok=True)
    attempt = folder.with_name(f"{folder.name}.attempt-{uuid.uuid4().hex[:8]}")
    attempt.mkdir()
    started = time.time()
    record = {k: p[k] for k in ("id", "sequence", "variant", "repeat", "seed", "deterministic", "hash")}
    record.update({"overrides": p["overrides"], "host": socket.gethostname(), "pid": os.getpid(),
                   "command": [p["program"], *_fill(p["command"], folder)]})
    try:
        record.update(_run_in(p, attempt))
    except Exception as e:  # anything at all: recorded against this run, the study goes on
        record.update({"status": "failed", "error": f"{type(e).__name__}: {e}"})
    record["wall_seconds"] = round(time.time() - started, 3)
    (attempt / "run.json").write_text(json.dumps(record, indent=1) + "\n")
    _swap_in(attempt, folder)
    return {**record, "resumed": False}


def _run_in(p: dict, attempt: Path) -> dict:
    if p["settings_text"] is not None:
        (attempt / "settings.yaml").write_text(p["settings_text"])
    with open(attempt / "stderr.txt", "w") as err:
        rc = subprocess.run([p["program"], *_fill(p["command"], attempt), "--out", str(attempt)],
                            stdout=subprocess.DEVNULL, stderr=err, stdin=subprocess.DEVNULL,
                            preexec_fn=_die_with_parent, start_new_session=True).returncode
    report_file = attempt / "report.json"
    if rc != 0:
        return {"status": "failed", "error": f"orbis run exited with {rc}: {_tail(attempt / 'stderr.txt')}"}
    report = json.loads(report_file.read_text())
    row = {"status": "ok", "error": "", **metrics_of(report), "rpe_rmse": math.nan}
    if p["rpe"]:
        rpe = subprocess.run([p["program"], *_fill(p["rpe"], attempt)], capture_output=True, text=True,
                             stdin=subprocess.DEVNULL, preexec_fn=_die_with_parent)
        if rpe.returncode == 0:
            row["rpe_rmse"] = json.loads(rpe.stdout)["rmse"]
        else:
            row["rpe_error"] = rpe.stderr.strip()[-300:]
    return row


def _swap_in(attempt: Path, folder: Path) -> None:
    """Replaces the run folder by the finished attempt (the older one is removed)."""
    old = None
    if folder.exists():
        old = folder.with_name(f"{folder.name}.old-{uuid.uuid4().hex[:8]}")
        folder.rename(old)
    attempt.rename(folder)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def remove_stale_attempts(runs_dir: Path) -> int:
    """Attempt folders left by killed workers or an interrupted study (call when no run is under way)."""
    stale = [d for d in runs_dir.glob("**/*.attempt-*") if d.is_dir()] + \
            [d for d in runs_dir.glob("**/*.old-*") if d.is_dir()]
    for d in stale:
        shutil.rmtree(d, ignore_errors=True)
    return len(stale)
