#!/usr/bin/env python3
"""benchmarks/python_overhead.py — per-frame cost of tracking from Python against C++.

Contract: on one sequence (default: the TUM teddy slice in ../shared/datasets with
examples/settings/TUM3.yaml; else a rendered 640 x 480 RGB-D loop), runs back to back
(1) the C++ program, `orbis run tum ... --json` (threaded mapping, as in real time), and
(2) orbis.RgbdSlam from Python in the same mode, frames read in the loop as the program reads
them (reading them all first made the C++ stages slower: cold caches), each track() call timed
with perf_counter around it; the two runs alternate which goes first. The binding's overhead is measured per frame: the call's wall time
seen from Python minus its C++ part (Slam::track, timed inside the binding: slam.track_times()),
whose median is reported as a share of the median C++ call; this is what the binding adds
(argument checks, array views, GIL release and re-acquisition, the result). Beside it, per-frame
medians of the two per-frame stages ("tracking: ORB extraction" + "tracking: total"), the same
statistic in both runs, for the comparison with the separate C++ program (on a shared machine,
run-to-run noise dominates that one). Prints a table and one JSON line. Usage:
  PYTHONPATH=build/release/python python3 benchmarks/python_overhead.py [--cli build/release/orbis]
      [--sequence PATH --settings FILE] [--deterministic] [--repeat N]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import orbis

ROOT = Path(__file__).resolve().parents[1]
STAGES = ("tracking: ORB extraction", "tracking: total")


def stage_medians(timing: dict[str, dict[str, float]]) -> float:
    return sum(timing[stage]["median"] for stage in STAGES)


def cpp_run(cli: Path, sequence: Path, settings: Path, deterministic: bool) -> float:
    with tempfile.TemporaryDirectory() as out:
        command = [str(cli), "run", "tum", str(sequence), "--settings", str(settings), "--out", out, "--json"]
        report = json.loads(subprocess.run(command + (["--deterministic"] if deterministic else []),
                                           check=True, capture_output=True, text=True).stdout)
    return stage_medians(report["timing_ms"])


def python_run(sequence: Path, settings: Path, deterministic: bool) -> dict[str, float]:
    slam = orbis.RgbdSlam(orbis.Settings.load(settings, sensor="rgbd"), deterministic=deterministic)
    walls = []
    for frame in orbis.datasets.tum(sequence):  # read in the loop, as orbis run reads them
        if frame.warnings:  # no depth map within 20 ms: orbis run skips these too
            continue
        image, depth, stamp = frame.image, frame.depth, frame.timestamp
        start = time.perf_counter()
        slam.track(image, depth, stamp)
        walls.append((time.perf_counter() - start) * 1000)
    slam.shutdown()
    inner = slam.track_times()  # the same calls' C++ part (Slam::track), ms
    timing = {s["stage"]: {"median": s["median_ms"]} for s in slam.timing()}
    return {"python_wall_ms": statistics.median(walls), "python_cpp_call_ms": statistics.median(inner),
            "python_stages_ms": stage_medians(timing),
            "binding_overhead_ms": statistics.median(w - c for w, c in zip(walls, inner))}


def default_sequence(cli: Path, scratch: Path) -> tuple[Path, Path]:
    teddy = ROOT.parent / "shared" / "datasets" / "tum_fr3_teddy_200"
    if teddy.is_dir():
        return teddy, ROOT / "examples" / "settings" / "TUM3.yaml"
    room = scratch / "room"
    subprocess.run([str(cli), "synth", str(room), "--layout", "tum", "--frames", "200", "--seed", "3"],
                   check=True, capture_output=True)
    return room, room / "settings.yaml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", type=Path, default=ROOT / "build" / "release" / "orbis")
    parser.add_argument("--sequence", type=Path)
    parser.add_argument("--settings", type=Path)
    parser.add_argument("--deterministic", action="store_true")
    parser.add_argument("--repeat", type=int, default=1, help="pairs of runs (C++ then Python)")
    a = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        sequence, settings = (a.sequence, a.settings) if a.sequence else default_sequence(a.cli, Path(scratch))
        rows = []
        for _ in range(a.repeat):
            row = {}
            for side in (("cpp", "python") if len(rows) % 2 == 0 else ("python", "cpp")):  # alternate who goes first
                if side == "cpp":
                    row["cpp_run_stages_ms"] = cpp_run(a.cli, sequence, settings, a.deterministic)
                else:
                    row.update(python_run(sequence, settings, a.deterministic))
            row["stages_percent"] = 100 * (row["python_stages_ms"] / row["cpp_run_stages_ms"] - 1)
            row["overhead_percent"] = 100 * row["binding_overhead_ms"] / row["python_cpp_call_ms"]
            rows.append(row)
    print(f"sequence {sequence} ({'deterministic' if a.deterministic else 'threaded'} mapping), per-frame medians in ms")
    print(f"{'C++ run: extraction+tracking':>29} | Python run: {'the same':>16} {'C++ call':>9} "
          f"{'wall':>8} {'wall - C++ call, per frame':>28}")
    for r in rows:
        print(f"{r['cpp_run_stages_ms']:29.3f} | {'':11}{r['python_stages_ms']:8.3f} ({r['stages_percent']:+5.1f}%) "
              f"{r['python_cpp_call_ms']:9.3f} {r['python_wall_ms']:8.3f} {r['binding_overhead_ms']:19.4f} "
              f"({r['overhead_percent']:.2f}%)")
    print(json.dumps({"sequence": str(sequence), "runs": rows}))


if __name__ == "__main__":
    main()
