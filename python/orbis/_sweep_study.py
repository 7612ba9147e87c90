"""orbis._sweep_study — study files of orbis.sweep: reading, checking and expanding into runs.

Contract: read_study_file() parses a YAML (.yaml/.yml) or TOML (.toml) study into a dict;
Study.build() checks it completely — every sequence path, settings file and ground truth exists,
every override names a run option or a settings key the orbis program reads (`orbis settings-keys
--json`, the reader's own list), every value has the right type — and expands it into Run objects
(sequences x variants x grid points x repeats). Every problem raises StudyError naming the study
file and the entry, before anything runs. Nothing here starts a run or writes a file.
"""

from __future__ import annotations

import difflib
import itertools
import json
import os
import re
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

DATASET_KINDS = ("tum", "euroc", "kitti", "kitti-raw")
SENSORS = ("mono", "stereo", "rgbd")
# Run options a variant or grid may set, with their type; every other key must be a settings key.
RUN_OPTIONS: dict[str, type | tuple[type, ...]] = {
    "deterministic": bool,     # orbis run --deterministic (False: threaded)
    "threaded": bool,          # the opposite of deterministic
    "loop": bool,              # False: --no-loop
    "no_loop": bool,
    "sensor": str,             # --sensor mono|stereo|rgbd
    "max_frames": int,         # --max-frames
    "realtime": bool,          # --realtime
    "budget": (int, float),    # feature budget as a factor of the settings file's ORBextractor.nFeatures
    "seed": int,               # System.seed
    "vocab": str,              # --vocab FILE
    "repeats": int,            # runs of this variant (seeds: one per listed seed)
    "seeds": list,
    "name": str,
}
SEQUENCE_KEYS = ("dataset", "path", "settings", "ground_truth", "gt_times", "sequence", "sensor", "max_frames",
                 "reference", "synth")
TOP_LEVEL_KEYS = ("name", "vars", "sequences", "variants", "grid", "repeats", "seeds", "max_frames", "reference_label")
# Where `orbis synth` puts a layout's ground truth (and KITTI's timestamps), relative to its folder.
SYNTH_GROUND_TRUTH = {"tum": ("groundtruth.txt", None),
                      "euroc": ("mav0/state_groundtruth_estimate0/data.csv", None),
                      "kitti": ("poses/00.txt", "sequences/00/times.txt")}


class StudyError(Exception):
    """A study that cannot run: the message names the study file and the entry at fault."""


def read_study_file(path: str | os.PathLike) -> dict:
    """The study file's contents as a dict (YAML or TOML, by extension)."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as e:
        raise StudyError(f"{path}: cannot read the study file ({e.strerror or e})") from None
    if path.suffix == ".toml":
        import tomllib
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise StudyError(f"{path}: not valid TOML: {e}") from None
    else:
        import yaml
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
            problem = getattr(e, "problem", None) or str(e)
            raise StudyError(f"{path}: not valid YAML{where}: {problem}") from None
    if not isinstance(data, dict):
        raise StudyError(f"{path}: expected a map of keys (name, sequences, variants, ...) at the top level")
    return data


def settings_keys(program: str) -> list[str]:
    """The settings keys the orbis program reads (`orbis settings-keys --json`)."""
    try:
        done = subprocess.run([program, "settings-keys", "--json"], capture_output=True, text=True, timeout=60)
    except OSError as e:
        raise StudyError(f"{program}: cannot run the orbis program ({e.strerror or e}); give it with --orbis") from None
    if done.returncode != 0:
        raise StudyError(f"{program}: `settings-keys --json` failed: {done.stderr.strip()}")
    return [k["name"] for k in json.loads(done.stdout)]


@dataclass
class Sequence:
    name: str
    dataset: str
    path: Path
    settings: Path | None = None
    ground_truth: Path | None = None
    gt_times: Path | None = None
    kitti_sequence: str | None = None
    sensor: str | None = None
    max_frames: int | None = None
    reference: dict[str, float] = field(default_factory=dict)
    synth: dict[str, Any] | None = None  # rendered by `orbis synth` into path before the runs


@dataclass
class Run:
    id: str                 # sequence/variant/rREPEAT, also the run's folder under runs/
    sequence: Sequence
    variant: str
    repeat: int
    options: dict[str, Any]             # run options (deterministic, loop, sensor, max_frames, ...)
    overrides: dict[str, Any]           # settings keys written into the run's settings file
    budget: float | None = None


@dataclass
class Study:
    name: str
    file: Path
    sequences: dict[str, Sequence]
    runs: list[Run]
    reference_label: str = "reference"

    @staticmethod
    def build(data: dict, file: str | os.PathLike, accepted_keys: list[str], out: str | os.PathLike,
              max_frames: int | None = None) -> "Study":
        """Checks a study file's dict and expands it; `out` is where rendered sequences go."""
        return _Builder(data, Path(file), accepted_keys, Path(out), max_frames).build()


class _Builder:
    def __init__(self, data: dict, file: Path, accepted: list[str], out: Path, max_frames: int | None):
        self.data, self.file, self.accepted, self.out, self.max_frames = data, file, accepted, out, max_frames
        self.base = file.resolve().parent

    def fail(self, where: str, what: str) -> StudyError:
        return StudyError(f"{self.file}: {where}: {what}")

    def build(self) -> Study:
        unknown = [k for k in self.data if k not in TOP_LEVEL_KEYS]
        if unknown:
            raise self.fail(f"key {unknown[0]}", f"unknown (the top level takes {', '.join(TOP_LEVEL_KEYS)})")
        self.vars = self.mapping(self.data.get("vars", {}), "vars")
        sequences = self.mapping(self.data.get("sequences"), "sequences")
        if not sequences:
            raise self.fail("sequences", "missing or empty: a study needs at least one sequence")
        seqs = {str(name): self.sequence(str(name), spec) for name, spec in sequences.items()}
        variants = self.variants()
        runs = [run for seq in seqs.values() for run in self.runs_of(seq, variants)]
        ids = [r.id for r in runs]
        duplicate = next((i for i in ids if ids.count(i) > 1), None)
        if duplicate:
            raise self.fail("variants", f"two runs get the same name {duplicate}: give the variants distinct names")
        name = str(self.data.get("name", self.file.stem))
        return Study(name, self.file, seqs, runs, str(self.data.get("reference_label", "reference")))

    # --- values -------------------------------------------------------------------------------
    def mapping(self, value: Any, where: str) -> dict:
        if value is None:
            return {}
        if not isinstance(value, dict):
            raise self.fail(where, f"expected a map, found {type(value).__name__} {value!r}")
        return value

    def expand(self, text: str, where: str) -> str:
        """${NAME} and ${NAME:-default}: the environment first, then the study's vars."""
        def one(m: re.Match) -> str:
            name, default = m.group(1), m.group(3)
            if name in os.environ:
                return os.environ[name]
            if name in self.vars:
                return self.expand(str(self.vars[name]), f"vars.{name}")
            if default is not None:
                return default
            raise self.fail(where, f"${{{name}}} is neither in the environment nor in vars")
        return re.sub(r"\$\{(\w+)(:-([^}]*))?\}", one, text)

    def path(self, value: Any, where: str, must_exist: bool = True) -> Path:
        if not isinstance(value, str):
            raise self.fail(where, f"expected a path, found {value!r}")
        p = Path(self.expand(value, where)).expanduser()
        p = p if p.is_absolute() else (self.base / p)
        p = Path(os.path.normpath(p))
        if must_exist and not p.exists():
            raise self.fail(where, f"{p} does not exist")
        return p

    # --- sequences ----------------------------------------------------------------------------
    def sequence(self, name: str, spec: Any) -> Sequence:
        where = f"sequence {name}"
        spec = self.mapping(spec, where)
        unknown = [k for k in spec if k not in SEQUENCE_KEYS]
        if unknown:
            raise self.fail(f"{where}, key {unknown[0]}", f"unknown (a sequence takes {', '.join(SEQUENCE_KEYS)})")
        if not re.fullmatch(r"[A-Za-z0-9._-]+", name):
            raise self.fail(where, "a sequence name may hold only letters, digits, '.', '_' and '-'")
        synth = spec.get("synth")
        if synth is not None:
            return self.rendered(name, spec, self.mapping(synth, f"{where}, synth"))
        dataset = spec.get("dataset")
        if dataset not in DATASET_KINDS:
            raise self.fail(f"{where}, dataset", f"expected one of {', '.join(DATASET_KINDS)}, found {dataset!r}")
        if "path" not in spec:
            raise self.fail(where, "needs a path (the sequence folder) or synth (a rendered sequence)")
        seq = Sequence(name, dataset, self.path(spec["path"], f"{where}, path"))
        self.sequence_options(seq, spec, where)
        return seq

    def rendered(self, name: str, spec: dict, synth: dict) -> Sequence:
        where = f"sequence {name}"
        layout = str(synth.get("layout", "tum"))
        if layout not in SYNTH_GROUND_TRUTH:
            raise self.fail(f"{where}, synth.layout", f"expected tum, euroc or kitti, found {layout!r}")
        for key, value in synth.items():
            if not isinstance(value, (str, int, float, bool)):
                raise self.fail(f"{where}, synth.{key}", f"expected a number, text or true, found {value!r}")
        folder = self.out / "sequences" / name
        gt, times = SYNTH_GROUND_TRUTH[layout]
        seq = Sequence(name, layout, folder, settings=folder / "settings.yaml", ground_truth=folder / gt,
                       gt_times=folder / times if times else None, synth={**synth, "layout": layout})
        self.sequence_options(seq, {k: v for k, v in spec.items() if k not in ("dataset", "path")}, where)
        return seq

    def sequence_options(self, seq: Sequence, spec: dict, where: str) -> None:
        if "settings" in spec:
            seq.settings = self.path(spec["settings"], f"{where}, settings")
        if "ground_truth" in spec:
            seq.ground_truth = self.path(spec["ground_truth"], f"{where}, ground_truth")
        if "gt_times" in spec:
            seq.gt_times = self.path(spec["gt_times"], f"{where}, gt_times")
        if "sequence" in spec:
            seq.kitti_sequence = str(spec["sequence"])
        if "sensor" in spec:
            seq.sensor = self.option("sensor", spec["sensor"], where)
        if "max_frames" in spec:
            seq.max_frames = self.option("max_frames", spec["max_frames"], where)
        for metric, value in self.mapping(spec.get("reference"), f"{where}, reference").items():
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise self.fail(f"{where}, reference.{metric}", f"expected a number, found {value!r}")
            seq.reference[str(metric)] = float(value)

    # --- variants -----------------------------------------------------------------------------
    def option(self, key: str, value: Any, where: str) -> Any:
        wanted = RUN_OPTIONS[key]
        ok = isinstance(value, wanted) and not (wanted in (int, (int, float)) and isinstance(value, bool))
        if not ok:
            kind = {bool: "true or false", int: "a whole number", str: "text", list: "a list"}.get(wanted, "a number")
            raise self.fail(f"{where}, {key}", f"expected {kind}, found {value!r}")
        if key == "sensor" and value not in SENSORS:
            raise self.fail(f"{where}, sensor", f"expected one of {', '.join(SENSORS)}, found {value!r}")
        if key in ("max_frames", "repeats") and value < (0 if key == "max_frames" else 1):
            raise self.fail(f"{where}, {key}", f"must be {'0 or more' if key == 'max_frames' else 'at least 1'}")
        if key == "budget" and not value > 0:
            raise self.fail(f"{where}, budget", "must be a positive factor of the file's ORBextractor.nFeatures")
        if key == "seeds" and not all(isinstance(s, int) and not isinstance(s, bool) for s in value):
            raise self.fail(f"{where}, seeds", f"expected a list of whole numbers, found {value!r}")
        return value

    def check_key(self, key: str, value: Any, where: str) -> None:
        if key in RUN_OPTIONS:
            self.option(key, value, where)
            return
        if key not in self.accepted:
            near = difflib.get_close_matches(key, self.accepted + list(RUN_OPTIONS), n=1)
            hint = f"; did you mean {near[0]}?" if near else ""
            raise self.fail(f"{where}, key {key}", "unknown: neither a run option "
                            f"({', '.join(k for k in RUN_OPTIONS if k not in ('name', 'seeds', 'repeats'))}) "
                            f"nor a settings key orbis reads (`orbis settings-keys`){hint}")
        if not isinstance(value, (int, float, str, list, dict)):
            raise self.fail(f"{where}, {key}", f"expected a value, found {value!r}")

    def variants(self) -> list[dict]:
        listed = self.data.get("variants") or [{"name": "default"}]
        if not isinstance(listed, list):
            raise self.fail("variants", "expected a list of maps (each a named set of overrides)")
        variants = []
        for i, v in enumerate(listed):
            v = dict(self.mapping(v, f"variant {i + 1}"))
            v.setdefault("name", f"v{i + 1}")
            for key, value in v.items():
                self.check_key(key, value, f"variant {v['name']}")
            variants.append(v)
        grid = self.mapping(self.data.get("grid"), "grid")
        if grid:
            points = []
            for key, values in grid.items():
                if not isinstance(values, list) or not values:
                    raise self.fail(f"grid, {key}", "expected a non-empty list of values")
                for value in values:
                    self.check_key(key, value, "grid")
                points.append([(key, value) for value in values])
            combined = []
            for v in variants:
                for point in itertools.product(*points):
                    label = ",".join(f"{k.split('.')[-1]}={val}" for k, val in point)
                    name = label if v["name"] == "default" and len(variants) == 1 else f"{v['name']},{label}"
                    combined.append({**v, **dict(point), "name": name})
            variants = combined
        for key in ("repeats", "seeds", "max_frames"):
            if key in self.data:
                self.option(key, self.data[key], "top level")
        return variants

    def runs_of(self, seq: Sequence, variants: list[dict]) -> list[Run]:
        runs = []
        for v in variants:
            where = f"variant {v['name']}"
            seeds = v.get("seeds", self.data.get("seeds"))
            count = len(seeds) if seeds else v.get("repeats", self.data.get("repeats", 1))
            options = {"deterministic": False, "loop": True, "sensor": seq.sensor,
                       "max_frames": self.max_frames if self.max_frames is not None
                       else v.get("max_frames", seq.max_frames if seq.max_frames is not None
                                  else self.data.get("max_frames", 0)),
                       "realtime": v.get("realtime", False), "vocab": None}
            if "threaded" in v:
                options["deterministic"] = not v["threaded"]
            if "deterministic" in v:
                options["deterministic"] = v["deterministic"]
            options["loop"] = v.get("loop", not v.get("no_loop", False))
            if "sensor" in v:
                options["sensor"] = v["sensor"]
            if "vocab" in v:
                options["vocab"] = str(self.path(v["vocab"], f"{where}, vocab"))
            overrides = {k: val for k, val in v.items() if k not in RUN_OPTIONS}
            if "seed" in v:
                overrides["System.seed"] = v["seed"]
            if (overrides or "budget" in v or seeds) and seq.settings is None:
                raise self.fail(f"{where}, sequence {seq.name}",
                                "overrides settings keys but the sequence has no settings file (give `settings`)")
            safe = re.sub(r"[^A-Za-z0-9._=,+-]", "_", str(v["name"]))
            for k in range(count):
                run_overrides = dict(overrides)
                if seeds:
                    run_overrides["System.seed"] = seeds[k]
                runs.append(Run(f"{seq.name}/{safe}/r{k}", seq, str(v["name"]), k, dict(options), run_overrides,
                                float(v["budget"]) if "budget" in v else None))
        return runs
