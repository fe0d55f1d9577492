#!/bin/sh
# The README's gate recipe ("Gate a shader edit in CI"), run as written in a
# scratch folder laid out as the source tree: the edit it makes must fail
# the gate (exit 1) and leave the Markdown summary it names. A recipe that
# no longer runs (a folder the shaders need left out of the copy, a flag
# renamed) fails here.
#   readme_gate_recipe.sh SOURCE_DIR BUILD_DIR
set -eu
src=$1
build=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp -r "$src/shaders" "$src/shared" "$work/"
mkdir -p "$work/reports" "$work/build/bench"
cp -r "$src/reports/baselines" "$work/reports/"
ln -s "$build/bench/depthbench" "$work/build/bench/depthbench"
recipe=$(awk '/^### Gate a shader edit in CI/ { found = 1 }
              found && /^```sh/ { inside = 1; next }
              inside && /^```/ { exit }
              inside { print }' "$src/README.md")
if [ -z "$recipe" ]; then
  echo "README.md has no sh block under '### Gate a shader edit in CI'" >&2
  exit 1
fi
cd "$work"
status=0
sh -eu -c "$recipe" || status=$?
if [ "$status" -ne 1 ]; then
  echo "the recipe exited $status; its edit must fail the gate (exit 1)" >&2
  exit 1
fi
if ! grep -q '^### depthbench gate: FAIL' gate.md; then
  echo "gate.md does not hold the failing gate's summary" >&2
  exit 1
fi
echo "README gate recipe: the gate failed as it should, gate.md written"
