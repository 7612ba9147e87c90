"""tests/python/test_sweep.py — orbis.sweep on tiny studies (a rendered 60-frame room, 12-frame runs).

Contract: a study expands into sequences x variants x grid points x repeats, the same from YAML
and TOML; a missing sequence path, an unknown settings key and a malformed file each raise a
StudyError naming the file and the entry before anything is written; a finished run is not run
again and a failed one is recorded with its error without stopping the study; a deterministic
run's trajectory is byte-identical to `orbis run --deterministic` with the same settings; a
2-worker local Dask cluster runs a study to the same table. Needs the orbis program (ctest sets
$ORBIS_CLI) and Dask (python3-distributed) for the cluster test.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from orbis import sweep
from orbis._sweep_run import derive_settings

FRAMES = 12


def write_study(folder: Path, room: Path, variants: str, extra: str = "", name: str = "study.yaml") -> Path:
    path = folder / name
    path.write_text(f"""name: tiny
max_frames: {FRAMES}
sequences:
  room:
    dataset: tum
    path: {room}
    settings: {room}/settings.yaml
    ground_truth: {room}/groundtruth.txt
    reference: {{ate: 0.01}}
variants:
{variants}
{extra}""")
    return path


@pytest.fixture()
def program(cli: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    monkeypatch.setenv("ORBIS", str(cli))
    return str(cli)


def test_expansion_covers_variants_grid_and_repeats(synthetic: Path, program: str, tmp_path: Path) -> None:
    study_file = write_study(tmp_path, synthetic, "  - {name: det, deterministic: true}\n"
                                                  "  - {name: thr, threaded: true, repeats: 2, no_loop: true}",
                             "grid:\n  ORBextractor.nFeatures: [500, 700]\n")
    study, out, _ = sweep.load(study_file, tmp_path / "out")
    ids = [r.id for r in study.runs]
    assert ids == ["room/det,nFeatures=500/r0", "room/det,nFeatures=700/r0", "room/thr,nFeatures=500/r0",
                   "room/thr,nFeatures=500/r1", "room/thr,nFeatures=700/r0", "room/thr,nFeatures=700/r1"]
    thr = study.runs[2]
    assert thr.overrides == {"ORBextractor.nFeatures": 500}
    assert not thr.options["deterministic"] and not thr.options["loop"] and thr.options["max_frames"] == FRAMES
    assert study.runs[0].options["deterministic"]
    assert not out.exists(), "loading a study writes nothing"
    # The same study in TOML expands to the same runs.
    toml = tmp_path / "study.toml"
    toml.write_text(f"""name = "tiny"
max_frames = {FRAMES}
[sequences.room]
dataset = "tum"
path = "{synthetic}"
settings = "{synthetic}/settings.yaml"
ground_truth = "{synthetic}/groundtruth.txt"
[[variants]]
name = "det"
deterministic = true
[[variants]]
name = "thr"
threaded = true
repeats = 2
no_loop = true
[grid]
"ORBextractor.nFeatures" = [500, 700]
""")
    assert [r.id for r in sweep.load(toml, tmp_path / "out")[0].runs] == ids
    # Seeds: one run per seed, each setting System.seed.
    seeded = write_study(tmp_path, synthetic, "  - {name: s, seeds: [4, 9]}", name="seeded.yaml")
    assert [r.overrides["System.seed"] for r in sweep.load(seeded, tmp_path / "out")[0].runs] == [4, 9]


def test_settings_overrides_and_budget() -> None:
    text = "%YAML:1.0\nCamera.fx: 500.0\nORBextractor.nFeatures: 1000\nLEFT.K: !!opencv-matrix\n   rows: 1\n   data: [1]\nThDepth: 40\n"
    out = derive_settings(text, {"Camera.fx": 480.5, "LEFT.K": {"rows": 1, "cols": 1, "data": [2]}, "Sensor": "rgbd"},
                          0.9, "x.yaml")
    assert "Camera.fx: 480.5\n" in out and "ORBextractor.nFeatures: 900\n" in out
    assert 'LEFT.K: {"rows": 1, "cols": 1, "data": [2]}\nThDepth: 40' in out, "a matrix block is replaced whole"
    assert out.endswith('Sensor: "rgbd"\n')


@pytest.mark.parametrize("case", ["missing path", "unknown key", "bad yaml", "bad toml", "bad value"])
def test_bad_input_is_a_clear_error_before_anything_runs(case: str, synthetic: Path, program: str,
                                                         tmp_path: Path) -> None:
    ok_variant = "  - {name: det, deterministic: true}"
    if case == "missing path":
        study = write_study(tmp_path, tmp_path / "no_such_sequence", ok_variant)
        expected = ["sequence room, path", "no_such_sequence does not exist"]
    elif case == "unknown key":
        study = write_study(tmp_path, synthetic, "  - {name: det, ORBextractor.nFeature: 800}")
        expected = ["variant det, key ORBextractor.nFeature", "unknown", "did you mean ORBextractor.nFeatures"]
    elif case == "bad yaml":
        study = write_study(tmp_path, synthetic, "  - {name: det, deterministic: true")
        expected = ["not valid YAML (line"]
    elif case == "bad toml":
        study = tmp_path / "study.toml"
        study.write_text("name = \"x\"\n[sequences.room\n")
        expected = ["not valid TOML", "line 2"]
    else:
        study = write_study(tmp_path, synthetic, "  - {name: det, deterministic: yes please}")
        expected = ["variant det, deterministic", "expected true or false"]
    out = tmp_path / "out"
    with pytest.raises(sweep.StudyError) as error:
        sweep.run(study, out, serial=True, log=lambda _: None)
    for text in expected:
        assert text in str(error.value)
    assert str(study) in str(error.value)
    assert not out.exists(), "nothing is written before the study is checked"
    # The command line: the same message, exit status 2.
    done = subprocess.run([sys.executable, "-m", "orbis.sweep", str(study), "--out", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 2 and expected[0] in done.stderr and not out.exists()


def read_table(folder: Path) -> dict[str, dict]:
    with open(folder / "results.csv", newline="") as f:
        return {r["id"]: r for r in csv.DictReader(f)}


def test_resume_failure_and_identity_with_orbis_run(synthetic: Path, program: str, tmp_path: Path) -> None:
    study = write_study(tmp_path, synthetic, "  - {name: det, deterministic: true, budget: 0.9}\n"
                                             "  - {name: broken, deterministic: true, Camera.fx: -1}")
    out = tmp_path / "out"
    first = sweep.run(study, out, serial=True, log=lambda _: None)
    rows = {r["id"]: r for r in first.rows}
    assert rows["room/det/r0"]["status"] == "ok" and rows["room/det/r0"]["frames"] == FRAMES
    assert rows["room/det/r0"]["rpe_rmse"] > 0 and rows["room/det/r0"]["keyframes"] > 0
    broken = rows["room/broken/r0"]
    assert broken["status"] == "failed" and "Camera.fx" in broken["error"] and "positive" in broken["error"]
    table = read_table(out)
    assert set(table) == {"room/det/r0", "room/broken/r0"} and table["room/broken/r0"]["status"] == "failed"
    assert (out / "summary.csv").is_file() and (out / "summary.md").is_file()
    # Byte-identical to the program run by hand with the run's settings file.
    det = out / "runs/room/det/r0"
    assert "ORBextractor.nFeatures: 900" in (det / "settings.yaml").read_text()
    by_hand = tmp_path / "by_hand"
    subprocess.run([program, "run", "tum", str(synthetic), "--settings", str(det / "settings.yaml"), "--deterministic",
                    "--max-frames", str(FRAMES), "--out", str(by_hand)], check=True, capture_output=True)
    assert (by_hand / "trajectory.txt").read_bytes() == (det / "trajectory.txt").read_bytes()
    # Again: the finished run is kept as it is, the failed one is tried again.
    record = json.loads((det / "run.json").read_text())
    second = sweep.run(study, out, serial=True, log=lambda _: None)
    rows = {r["id"]: r for r in second.rows}
    assert rows["room/det/r0"]["resumed"] and json.loads((det / "run.json").read_text()) == record
    assert rows["room/broken/r0"]["status"] == "failed"
    assert not list(out.glob("runs/**/*.attempt-*"))
    # A changed input (another budget) is a different run: it runs again.
    study.write_text(study.read_text().replace("budget: 0.9", "budget: 0.8"))
    third = {r["id"]: r for r in sweep.run(study, out, serial=True, log=lambda _: None).rows}
    assert not third["room/det/r0"].get("resumed") and third["room/det/r0"]["status"] == "ok"


def test_two_worker_local_cluster(synthetic: Path, program: str, tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    study = write_study(tmp_path, synthetic, "  - {name: det, deterministic: true}\n"
                                             "  - {name: thr, threaded: true, repeats: 2}\n"
                                             "  - {name: lean, deterministic: true, ORBextractor.nFeatures: 600}")
    out = tmp_path / "out"
    lines: list[str] = []
    result = sweep.run(study, out, workers=2, log=lines.append)
    assert [r["status"] for r in result.rows] == ["ok"] * 4
    assert any("2 workers" in line for line in lines) and any("4/4 done" in line for line in lines)
    assert {r["pid"] for r in result.rows}.isdisjoint({os.getpid()}), "the runs ran on the workers"
    summary = {(s["sequence"], s["variant"]): s for s in result.summary}
    assert summary[("room", "thr")]["runs"] == 2 and summary[("room", "lean")]["ratio_reference"] > 0
    assert table_has_timing(out)


def table_has_timing(out: Path) -> bool:
    header = (out / "results.csv").read_text().splitlines()[0]
    return "median_ms." in header and "set.ORBextractor.nFeatures" in header
