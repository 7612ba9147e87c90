"""orbis.sweep — evaluation at scale: sequences x settings x repeats, on one machine or a Dask cluster.

Contract: a study file (YAML or TOML; docs/guide/sweep.md) lists sequences (any `orbis run` input
with its ground truth, or one `orbis synth` renders), variants and a grid of overrides (any
settings key the reader accepts, the sensor, the feature budget, threaded or deterministic, loop
closing, max frames, seeds) and repeats. run() checks the whole study before anything runs (a
missing path, an unknown key or a malformed file raises StudyError), renders the synthetic
sequences, expands the runs and executes each with the `orbis` program in its own folder
(OUT/runs/SEQUENCE/VARIANT/rN) — on a local Dask cluster (one single-threaded worker per core),
on a running Dask scheduler (`scheduler="tcp://HOST:8786"`), or serially. A finished run (its
report.json and the SHA-256 of its inputs) is not run again; a failed run is recorded with its
error and the study goes on; runs lost with a killed worker are run again by Dask. It writes
OUT/results.csv (+ .parquet with pyarrow), OUT/summary.csv and .md, OUT/plots/*.png.

    python3 -m orbis.sweep STUDY.yaml [--out DIR] [--workers N | --scheduler tcp://HOST:8786 | --serial]
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from ._sweep_report import read_summary, summarise, write_plots, write_summary, write_table
from ._sweep_run import execute, finished_row, plan, remove_stale_attempts
from ._sweep_study import Study, StudyError, read_study_file, settings_keys

__all__ = ["Study", "StudyError", "StudyResult", "find_program", "load", "run", "main"]


def find_program(given: str | os.PathLike | None = None) -> str:
    """The orbis program: the argument, $ORBIS, $ORBIS_CLI, the build tree's, or `orbis` on PATH."""
    build_tree = Path(__file__).resolve().parents[2] / "orbis"  # build/release/python/orbis/sweep.py
    for candidate in (given, os.environ.get("ORBIS"), os.environ.get("ORBIS_CLI")):
        if candidate:
            if not (Path(candidate).is_file() and os.access(candidate, os.X_OK)):
                raise StudyError(f"{candidate}: no such orbis program")
            return str(Path(candidate).resolve())
    if build_tree.is_file():
        return str(build_tree)
    found = shutil.which("orbis")
    if not found:
        raise StudyError("no orbis program: give it with --orbis PATH (or $ORBIS)")
    return found


def load(study_file: str | os.PathLike, out: str | os.PathLike | None = None, program: str | None = None,
         max_frames: int | None = None, edit: Callable[[dict], None] | None = None) -> tuple[Study, Path, str]:
    """Reads and checks a study (edit may change its dict first); returns it, its folder and the program."""
    study_file = Path(study_file)
    data = read_study_file(study_file)
    if edit:
        edit(data)
    program = find_program(program)
    out = Path(out) if out else Path.cwd() / f"sweep_{study_file.stem}"
    study = Study.build(data, study_file, settings_keys(program), out.resolve(), max_frames)
    return study, out.resolve(), program


@dataclass
class StudyResult:
    folder: Path
    rows: list[dict]
    summary: list[dict]
    files: list[Path] = field(default_factory=list)
    interrupted: bool = False

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.rows if r.get("status") != "ok"]


class Progress:
    """done/failed/remaining and an estimate of the time left, one line per finished run."""

    def __init__(self, total: int, resumed: int, log: Callable[[str], None]):
        self.total, self.resumed, self.log = total, resumed, log
        self.done = self.failed = 0
        self.started = time.time()

    def update(self, row: dict) -> None:
        self.done += 1
        self.failed += row.get("status") != "ok"
        remaining = self.total - self.resumed - self.done
        elapsed = time.time() - self.started
        eta = elapsed / self.done * remaining
        what = f"ATE {1000 * row['ate_rmse']:.2f} mm" if row.get("status") == "ok" and row.get("ate_rmse") == row.get(
            "ate_rmse") and row.get("ate_rmse") is not None else (row.get("error") or "")[:100]
        self.log(f"[sweep] {self.resumed + self.done}/{self.total} done ({self.failed} failed), {remaining} remaining, "
                 f"ETA {_duration(eta)} | {row['id']} {row.get('status')} {what}")


def _duration(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds // 60}m{seconds % 60:02d}s" if seconds >= 60 else f"{seconds}s"


def _render(study: Study, program: str, log: Callable[[str], None]) -> None:
    """Renders each synthetic sequence once (kept while its synth arguments stay the same)."""
    for seq in study.sequences.values():
        if seq.synth is None:
            continue
        stamp = seq.path / "synth.json"
        wanted = json.dumps(seq.synth, sort_keys=True)
        if stamp.is_file() and stamp.read_text() == wanted and seq.settings.is_file():
            continue
        args = [program, "synth", str(seq.path)]
        for key, value in seq.synth.items():
            if value is True:
                args.append(f"--{key.replace('_', '-')}")
            elif value is not False:
                args += [f"--{key.replace('_', '-')}", str(value)]
        log(f"[sweep] rendering {seq.name}: {' '.join(args[1:])}")
        done = subprocess.run(args, capture_output=True, text=True)
        if done.returncode != 0:
            raise StudyError(f"{study.file}: sequence {seq.name}: orbis synth failed: {done.stderr.strip()}")
        stamp.write_text(wanted)


def _failed_row(p: dict, error: str) -> dict:
    keep = ("id", "sequence", "variant", "repeat", "seed", "deterministic", "hash", "overrides")
    return {**{k: p[k] for k in keep}, "status": "failed", "error": error, "resumed": False}


def _dashboard(client) -> str:
    """The dashboard's address if its status page answers (the scheduler names one even without bokeh)."""
    import urllib.request
    link = client.dashboard_link
    try:
        direct = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # the scheduler itself, no proxy
        with direct.open(link, timeout=3) as page:
            # Without bokeh the scheduler still answers, with a page that asks for it.
            if page.status == 200 and b"needs bokeh" not in page.read(2000):
                return link
    except OSError:
        pass
    return f"none ({link} needs bokeh on the scheduler's machine)"


def _run_serial(plans: list[dict], progress: Progress) -> list[dict]:
    rows = []
    for p in plans:
        rows.append(execute(p))
        progress.update(rows[-1])
    return rows


def _run_dask(plans: list[dict], progress: Progress, scheduler: str | None, workers: int | None,
              log: Callable[[str], None]) -> list[dict]:
    from distributed import Client, LocalCluster, as_completed
    cluster = None
    if scheduler:
        client = Client(scheduler, timeout="30s")
    else:
        cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                               dashboard_address=":8787", silence_logs=logging.ERROR)
        client = Client(cluster)
    rows = []
    futures = []
    try:
        info = client.scheduler_info()
        log(f"[sweep] Dask scheduler {info.get('address')}, {len(info.get('workers', {}))} workers; "
            f"dashboard: {_dashboard(client)}")
        futures = [client.submit(execute, p, key=f"orbis-run-{p['id']}-{p['hash'][:12]}") for p in plans]
        by_key = {f.key: p for f, p in zip(futures, plans)}
        for future in as_completed(futures):
            try:
                row = future.result()
            except Exception as e:  # the task itself never raises: this is Dask giving up on it
                row = _failed_row(by_key[future.key], f"{type(e).__name__}: {e}")
            rows.append(row)
            progress.update(row)
    finally:
        if futures:
            client.cancel(futures)
        client.close()
        if cluster is not None:
            cluster.close()
    return rows


def collect(study: Study, folder: Path, program: str) -> list[dict]:
    """The rows of every run of the study already recorded in its folder (finished or failed)."""
    rows = []
    for p in (plan(r, program, folder) for r in study.runs):
        row = finished_row(p)
        if row is None:
            try:
                record = json.loads((Path(p["folder"]) / "run.json").read_text())
            except (OSError, ValueError):
                continue
            if record.get("hash") != p["hash"]:
                continue
            row = record
        rows.append(row)
    return rows


def report(study: Study, folder: Path, rows: list[dict], baseline: str | os.PathLike | None = None) -> StudyResult:
    """Writes the table, the summary and the plots of the rows given."""
    references = {name: seq.reference for name, seq in study.sequences.items()}
    summary = summarise(rows, references, read_summary(baseline) if baseline else None)
    files = write_table(rows, folder)
    write_summary(summary, folder, study.reference_label)
    files += [folder / "summary.csv", folder / "summary.md"]
    files += write_plots(rows, summary, folder, study.name)
    return StudyResult(folder, rows, summary, files)


def run(study_file: str | os.PathLike, out: str | os.PathLike | None = None, *, scheduler: str | None = None,
        workers: int | None = None, serial: bool = False, program: str | None = None,
        max_frames: int | None = None, baseline: str | os.PathLike | None = None, rerun: bool = False,
        edit: Callable[[dict], None] | None = None, log: Callable[[str], None] = print) -> StudyResult:
    """Checks, expands and executes a study; returns its rows and summary (see the module's contract)."""
    study, folder, program = load(study_file, out, program, max_frames, edit)
    if baseline and not (Path(baseline).is_file() or (Path(baseline) / "summary.csv").is_file()):
        raise StudyError(f"{baseline}: no baseline summary (give an earlier study's folder or its summary.csv)")
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(study.file, folder / f"study{study.file.suffix}")
    _render(study, program, log)
    try:
        plans = [plan(r, program, folder) for r in study.runs]
    except ValueError as e:
        raise StudyError(f"{study.file}: {e}") from None
    finished = [] if rerun else [row for row in map(finished_row, plans) if row]
    done_ids = {row["id"] for row in finished}
    todo = [p for p in plans if p["id"] not in done_ids]
    log(f"[sweep] {study.name}: {len(plans)} runs ({len(study.sequences)} sequences), {len(finished)} already "
        f"finished, {len(todo)} to run -> {folder}")
    progress = Progress(len(plans), len(finished), log)
    new_rows: list[dict] = []
    interrupted = False
    try:
        if todo:
            new_rows = _run_serial(todo, progress) if serial else _run_dask(todo, progress, scheduler, workers, log)
    except KeyboardInterrupt:
        interrupted = True
        log(f"[sweep] interrupted: {progress.resumed + progress.done} of {len(plans)} runs recorded; run the same "
            "command again to run only the rest")
    if todo and not interrupted:
        log(f"[sweep] {progress.done} runs in {time.time() - progress.started:.1f} s ({progress.failed} failed)")
    if not interrupted:
        remove_stale_attempts(folder / "runs")
    # This session's rows as they came back (a run Dask gave up on has no folder), then the recorded.
    fresh = {row["id"]: row for row in new_rows}
    rows = list(fresh.values()) + [row for row in collect(study, folder, program) if row["id"] not in fresh]
    result = report(study, folder, rows, baseline)
    result.interrupted = interrupted
    return result


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m orbis.sweep", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", help="the study file (.yaml, .yml or .toml)")
    ap.add_argument("--out", help="the study's folder (default: ./sweep_STUDYNAME); runs resume from it")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler (tcp://HOST:8786)")
    where.add_argument("--workers", type=int, metavar="N", help="local cluster of N workers (default: one per core)")
    where.add_argument("--serial", action="store_true", help="no Dask: the runs one after another in this process")
    ap.add_argument("--orbis", metavar="PATH", help="the orbis program (default: $ORBIS, the build tree's, PATH)")
    ap.add_argument("--max-frames", type=int, metavar="N", help="every run processes at most N frames")
    ap.add_argument("--baseline", metavar="DIR", help="an earlier study's folder (or summary.csv): ATE ratios to it")
    ap.add_argument("--rerun", action="store_true", help="run every run again, finished or not")
    ap.add_argument("--dry-run", action="store_true", help="check the study and list its runs, run nothing")
    ap.add_argument("--report-only", action="store_true", help="table, summary and plots of the runs recorded")
    args = ap.parse_args(argv)
    try:
        if args.dry_run or args.report_only:
            study, folder, program = load(args.study, args.out, args.orbis, args.max_frames)
            if args.dry_run:
                for r in study.runs:
                    p = plan(r, program, folder)
                    print(f"{p['id']}: orbis {' '.join(p['command'])}"
                          + (f"  [{', '.join(f'{k}={v}' for k, v in p['overrides'].items())}]" if p["overrides"] else ""))
                print(f"{len(study.runs)} runs")
                return 0
            result = report(study, folder, collect(study, folder, program), args.baseline)
        else:
            result = run(args.study, args.out, scheduler=args.scheduler, workers=args.workers, serial=args.serial,
                         program=args.orbis, max_frames=args.max_frames, baseline=args.baseline, rerun=args.rerun)
    except StudyError as e:
        print(f"orbis.sweep: error: {e}", file=sys.stderr)
        return 2
    print((result.folder / "summary.md").read_text())
    for row in result.failed:
        print(f"failed: {row['id']}: {row.get('error')}", file=sys.stderr)
    print("outputs: " + ", ".join(str(f) for f in result.files))
    if result.interrupted:
        return 130
    return 1 if result.rows and len(result.failed) == len(result.rows) else 0


if __name__ == "__main__":
    sys.exit(main())
