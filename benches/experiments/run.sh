#!/usr/bin/env bash
# Ways to walk the BVH faster that were tried for issue #23 and not kept: each
# is a patch against commit BASE below, timed against that commit's own build in
# one run, round after round, so that a busy machine slows both alike.
#
#   benches/experiments/run.sh [ROUNDS [SCENE [PATCH...]]]
#
# Defaults: 3 rounds, the scene `raystep generate spheres --count 100000 --seed 7`
# (SCENE `figure1`: the built-in scene at 1920 × 1080; "" for the default when
# naming patches), every patch of this folder. Each patch is applied to a
# worktree of BASE (under $CARGO_TARGET_DIR/experiments, target/experiments by
# default), on top of the patch its first line names if that line says
# "Applies after: OTHER.patch", and built there;
# then each round runs `raystep bench SCENE --runs 5 --no-yardstick --json` with
# BASE's binary and each patched one, and prints the fast engine's median frame on
# two threads and on one. The README beside this script says what each patch is
# and what it measured. (The worktree stays for the next run; `git worktree remove
# --force target/experiments/tree` removes it.)
set -euo pipefail
BASE=a94aa1f
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
target=${CARGO_TARGET_DIR:-$root/target}
work=$target/experiments
rounds=${1:-3}
scene=${2:-}
shift $(($# > 2 ? 2 : $#))
patches=()
for p in "$@"; do
  patches+=("$(cd "$(dirname "$p")" && pwd)/$(basename "$p")")
done
if [[ ${#patches[@]} -eq 0 ]]; then
  patches=("$here"/*.patch)
fi
mkdir -p "$work/bin"

tree=$work/tree
if [[ ! -d $tree ]]; then
  git -C "$root" worktree add --detach "$tree" "$BASE" >/dev/null
fi
build() { # name [patch]
  git -C "$tree" reset -q --hard "$BASE"
  git -C "$tree" clean -qfd
  if [[ -n ${2:-} ]]; then
    # A patch that says "Applies after: OTHER.patch" goes on top of that one.
    local after
    after=$(sed -n 's/^Applies after: //p' "$2" | head -n 1)
    if [[ -n $after ]]; then git -C "$tree" apply "$(dirname "$2")/$after"; fi
    git -C "$tree" apply "$2"
  fi
  (cd "$tree" && CARGO_TARGET_DIR=$work/build cargo build --release -q)
  cp "$work/build/release/raystep" "$work/bin/$1"
}
echo "building $BASE and ${#patches[@]} patched copies" >&2
build base
names=(base)
for p in "${patches[@]}"; do
  name=$(basename "$p" .patch)
  build "$name" "$p"
  names+=("$name")
done

if [[ -z $scene ]]; then
  scene=$work/spheres-100000.toml
  "$work/bin/base" generate spheres --count 100000 --seed 7 >"$scene"
fi
args=("$scene")
if [[ $scene == figure1 ]]; then
  args=()
fi
echo "round  binary               2 threads   1 thread   (fast engine, median of 5 frames)"
for r in $(seq 1 "$rounds"); do
  for name in "${names[@]}"; do
    "$work/bin/$name" bench "${args[@]}" --runs 5 --no-yardstick --json 2>/dev/null |
      python3 -c "
import json, sys
d = json.load(sys.stdin)
print(f\"{$r:5}  {'$name':18}  {d['median_s']*1e3:7.1f} ms  {d['one_thread_median_s']*1e3:7.1f} ms\")"
  done
done
