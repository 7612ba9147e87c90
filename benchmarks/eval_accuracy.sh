#!/usr/bin/env bash
# One-command accuracy report (see eval_accuracy.py): the real slices and the rendered loops,
# deterministic at three feature budgets and threaded (three runs), ATE, RPE, keyframes, map
# points, tracked frames; a table (WORK/report.md) and a plot of the ratios to ORB-SLAM2
# (WORK/ratios.png). About 6 minutes on two idle cores (10 while four builds share them).
#   benchmarks/eval_accuracy.sh [--label L] [--baseline OLD_WORK/results.json] [--threaded-runs N]
# Environment: ORBIS (default build/release/orbis), ORBIS_DATA (default ../shared/datasets),
# WORK (scratch folder, default /tmp/orbis_eval).
# The plot needs matplotlib: the first python3 that has it.
for py in python3 /usr/bin/python3; do
  if "$py" -c 'import matplotlib' 2>/dev/null; then exec "$py" "$(dirname "$0")/eval_accuracy.py" "$@"; fi
done
echo "eval_accuracy: no python3 with matplotlib" >&2
exit 1
