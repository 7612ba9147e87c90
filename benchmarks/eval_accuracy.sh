#!/usr/bin/env bash
# One-command accuracy report (see eval_accuracy.py): the study benchmarks/studies/accuracy.yaml
# (the real slices and the rendered loops, deterministic at three feature budgets and threaded,
# three runs) run by orbis.sweep on a local Dask cluster, then ATE, RPE, keyframes, map points,
# tracked frames in a table (WORK/report.md) and a plot of the ratios to ORB-SLAM2
# (WORK/ratios.png), beside the sweep's own results.csv, summary.md and plots/.
#   benchmarks/eval_accuracy.sh [--label L] [--baseline OLD_WORK/results.json] [--threaded-runs N]
#                               [--workers N | --scheduler tcp://HOST:8786 | --serial] [--max-frames N]
# Environment: ORBIS (default BUILD/orbis), ORBIS_BUILD (default build/release: its python/ has the
# orbis package), ORBIS_DATA (default ../shared/datasets), WORK (the study folder, default
# /tmp/orbis_eval; an interrupted report resumes from it).
root=$(cd "$(dirname "$0")/.." && pwd)
build=${ORBIS_BUILD:-$root/build/release}
export ORBIS=${ORBIS:-$build/orbis}
export PYTHONPATH="$build/python${PYTHONPATH:+:$PYTHONPATH}"
# The first python3 with what the report needs: the orbis module, Dask and matplotlib.
for py in python3 /usr/bin/python3; do
  if "$py" -c 'import orbis, distributed, matplotlib' 2>/dev/null; then exec "$py" "$root/benchmarks/eval_accuracy.py" "$@"; fi
done
echo "eval_accuracy: no python3 imports orbis (from $build/python), distributed and matplotlib (scripts/install-deps, scripts/build)" >&2
exit 1
