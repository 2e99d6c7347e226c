#!/usr/bin/env bash
# raystep's fast engine against Intel Embree 3 on generated scenes of many spheres,
# the two run in turn, round after round, so that a busy machine slows both alike.
#
#   benches/embree/run.sh build                 build the Embree program only
#   benches/embree/run.sh [ROUNDS [RUNS [COUNTS...]]]
#
# Defaults: 3 rounds of 3 timed runs each (after a warm-up), at 10, 1,000 and
# 100,000 spheres (`raystep generate spheres --count N --seed 7`), 1920 × 1080,
# with every stage and with primary and shadow rays only (`--without reflection`).
# Needs Debian's libembree-dev and g++ (apt-get install libembree-dev g++). The
# program is built into $CARGO_TARGET_DIR/embree/spheres (target/embree/spheres);
# `raystep chart --scale --embree PATH` runs it beside raystep's points. With
# RAYSTEP=path/to/raystep, that binary is timed (and this tree's is not built).
#
# Prints one line per round and measurement, then for each scene the min–max over
# the rounds of both programs' rays per second and of their ratios (raystep's rays
# per second over Embree's: above 1, raystep is faster), timed two ways: the
# frame without building the tree (Embree's frame; raystep's rows alone, its
# `trace_rays_per_s`), and the frame with each program's own tree build added
# (raystep's whole frame, `rays_per_s`; Embree's frame plus its build). Each counts its own rays;
# the two trace the same paths, up to the rounding of float32 (Embree's rays)
# against float64 (raystep's), so the counts differ by a few per cent at most.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
target=${CARGO_TARGET_DIR:-$root/target}
program=$target/embree/spheres

build() {
  mkdir -p "$target/embree"
  g++ -O3 -march=native -std=c++17 -Wall -Wextra -o "$program" "$here/spheres.cpp" \
    -lembree3 -lpthread
}

if [[ ${1:-} == build ]]; then
  build
  echo "$program"
  exit 0
fi

rounds=${1:-3}
runs=${2:-3}
shift $(($# < 2 ? $# : 2))
counts=("$@")
[[ ${#counts[@]} -gt 0 ]] || counts=(10 1000 100000)

# RAYSTEP=path/to/raystep times that binary instead of building this tree's.
if [[ -z ${RAYSTEP:-} ]]; then
  (cd "$root" && cargo build --release --quiet)
fi
raystep=${RAYSTEP:-$target/release/raystep}
build
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
threads=$(nproc)

echo "raystep $(git -C "$root" rev-parse --short HEAD), Embree $(dpkg-query -W -f '${Version}' libembree-dev 2>/dev/null || echo '?'), $threads threads, $rounds rounds of $runs runs"
results=$work/results.tsv
for count in "${counts[@]}"; do
  "$raystep" generate spheres --count "$count" --seed 7 >"$work/$count.toml"
done
for round in $(seq "$rounds"); do
  for count in "${counts[@]}"; do
    for mode in all primary+shadow; do
      flags=() embree_flags=()
      if [[ $mode == primary+shadow ]]; then
        flags=(--without reflection) embree_flags=(--without-reflection)
      fi
      json=$("$raystep" bench "$work/$count.toml" --runs "$runs" --no-yardstick --json \
        --threads "$threads" -q "${flags[@]}")
      r_rays=$(jq -r .trace_rays_per_s <<<"$json")
      r_ms=$(jq -r '.trace_s * 1000' <<<"$json")
      r_frame_ms=$(jq -r '.median_s * 1000' <<<"$json")
      r_count=$(jq -r .rays <<<"$json")
      speedup=$(jq -r '.thread_speedup // 0' <<<"$json")
      row=$("$program" --runs "$runs" --threads "$threads" "${embree_flags[@]}" \
        "$work/$count.toml" | tail -1)
      IFS=, read -r _ _ _ _ _ _ e_build e_ms _ _ e_count _ _ _ e_mrays <<<"$row"
      printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$round" "$count" "$mode" \
        "$r_ms" "$r_rays" "$r_count" "$e_ms" "$e_mrays" "$e_count" "$e_build" "$r_frame_ms" >>"$results"
      printf 'round %s  %6s spheres  %-14s raystep %8.1f ms of rows, %8.1f ms a frame, %6.1f Mray/s (%s rays, 2 threads %.2f× 1)   Embree %8.1f ms %6.1f Mray/s (%s rays, build %.1f ms)\n' \
        "$round" "$count" "$mode" "$r_ms" "$r_frame_ms" "$(jq -n "$r_rays / 1e6")" "$r_count" "$speedup" \
        "$e_ms" "$e_mrays" "$e_count" "$e_build"
    done
  done
done
echo
echo "min–max over $rounds rounds (ratio: raystep's rays per second over Embree's; without"
echo "the trees' builds, then with each program's build added to its frame)"
python3 - "$results" <<'EOF'
import sys, collections
rows = collections.defaultdict(list)
for line in open(sys.argv[1]):
    _, count, mode, r_ms, r_rays, r_count, e_ms, e_mrays, e_count, e_build, r_frame = line.split('\t')
    # With the builds: raystep's whole frame (its build is part of it), Embree's
    # frame plus its build.
    with_build = (float(r_count) / float(r_frame)) / (float(e_count) / (float(e_ms) + float(e_build)))
    rows[(int(count), mode)].append((float(r_ms), float(r_rays) / 1e6, float(e_ms), float(e_mrays), float(e_build), with_build))
span = lambda xs, f: f"{f.format(min(xs))}–{f.format(max(xs))}"
print(f"{'spheres':>8} {'rays':<15} {'raystep ms':>13} {'Mray/s':>11} {'Embree ms':>13} {'Mray/s':>11} {'build ms':>11} {'ratio':>11} {'with builds':>12}")
for (count, mode), v in sorted(rows.items()):
    col = lambda i: [x[i] for x in v]
    ratio = [x[1] / x[3] for x in v]
    print(f"{count:>8} {mode:<15} {span(col(0), '{:.0f}'):>13} {span(col(1), '{:.1f}'):>11} "
          f"{span(col(2), '{:.0f}'):>13} {span(col(3), '{:.1f}'):>11} {span(col(4), '{:.1f}'):>11} {span(ratio, '{:.2f}'):>11} {span(col(5), '{:.2f}'):>12}")
EOF
