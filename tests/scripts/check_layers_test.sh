#!/usr/bin/env bash
# Tests scripts/check-layers on small fake trees in a temporary folder, against the real layer
# table: a clean tree passes silently; a lower module including a higher one, two peers including
# each other, a relative include climbing into another module and an unknown folder each fail
# with the expected line; an allowlisted include passes, and a stale allowlist entry fails.
# Usage: check_layers_test.sh PATH/TO/check-layers
set -euo pipefail

check=${1:?usage: check_layers_test.sh PATH/TO/check-layers}
layers=$(dirname "$check")/layers.txt
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

# add FILE LINE...: writes a file of the fake tree.
add() {
  local file=$work/tree/$1
  shift
  mkdir -p "$(dirname "$file")"
  printf '%s\n' "$@" >"$file"
}

# expect NAME STATUS EXPECTED-OUTPUT [ALLOWLIST-LINES...]: runs the check on the tree and compares.
expect() {
  local name=$1 want_status=$2 want_output=$3
  shift 3
  printf '%s\n' "$@" >"$work/allowed.txt"
  local output status=0
  output=$("$check" --root "$work/tree" --layers "$layers" --allowed "$work/allowed.txt" 2>&1) || status=$?
  if [[ $status != "$want_status" || $output != "$want_output" ]]; then
    echo "FAIL $name: exit $status (want $want_status), output:"
    echo "$output"
    echo "wanted:"
    echo "$want_output"
    failures=$((failures + 1))
  else
    echo "ok   $name"
  fi
}

# A clean tree: each module includes only what lies below it.
add include/orbis/util/error.hpp '#pragma once'
add include/orbis/version.hpp '#pragma once'
add include/orbis/geometry/se3.hpp '#pragma once' '#include "orbis/util/error.hpp"' '#include "orbis/version.hpp"'
add include/orbis/optim/problem.hpp '#pragma once' '#include "orbis/geometry/se3.hpp"'
add include/orbis/io/bal.hpp '#pragma once' '#include "orbis/optim/problem.hpp"'
add include/orbis/map/map.hpp '#pragma once' '#include "orbis/optim/problem.hpp"'
add src/tracking/tracker.cpp '#include "orbis/map/map.hpp"' '#include "local.hpp"'
add src/mapping/mapper.cpp '#include "orbis/map/map.hpp"'
add src/cli/main.cpp '#include "orbis/io/bal.hpp"' '#include "command.hpp"'
add adapters/src/tum.cpp '#include "orbis/io/bal.hpp"' '#include "orbis/adapters/dataset.hpp"'
expect "clean tree passes" 0 ""

# Lower including higher: optim must not include io.
add include/orbis/optim/problem.hpp '#pragma once' '#include "orbis/geometry/se3.hpp"' '  #  include "orbis/io/bal.hpp"'
expect "optim including io fails" 1 \
  "include/orbis/optim/problem.hpp:3: optim includes io (io is above optim)"
add include/orbis/optim/problem.hpp '#pragma once' '#include "orbis/geometry/se3.hpp"'

# Thread modules are peers.
add src/tracking/tracker.cpp '#include "orbis/map/map.hpp"' '#include "orbis/mapping/local_mapper.hpp"'
expect "tracking including mapping fails" 1 \
  "src/tracking/tracker.cpp:2: tracking includes mapping (tracking and mapping are peers: neither may include the other)"
expect "an allowlisted include passes" 0 "" \
  "# reason" "src/tracking/tracker.cpp -> orbis/mapping/local_mapper.hpp  # being removed"
add src/tracking/tracker.cpp '#include "orbis/map/map.hpp"'
expect "a stale allowlist entry fails" 1 \
  "$work/allowed.txt:2: 'src/tracking/tracker.cpp -> orbis/mapping/local_mapper.hpp' no longer occurs: remove it from the allowlist" \
  "# reason" "src/tracking/tracker.cpp -> orbis/mapping/local_mapper.hpp  # being removed"

# A private header of a higher module reached by a relative path.
add src/geometry/so3.cpp '#include "../io/private.hpp"'
expect "a relative include into a higher module fails" 1 \
  "src/geometry/so3.cpp:1: geometry includes io (io is above geometry)"
rm "$work/tree/src/geometry/so3.cpp"

# A folder the table does not know.
add src/lidar/scan.cpp '#include "orbis/map/map.hpp"'
expect "an unknown module fails" 1 \
  "src/lidar/scan.cpp:1: lidar includes map (lidar is not in layers.txt: add the folder to the table)"
rm "$work/tree/src/lidar/scan.cpp"

expect "the tree is clean again" 0 ""

if ((failures)); then
  echo "$failures case(s) failed"
  exit 1
fi
