#!/usr/bin/env bash
# bonescope against assimp (Debian's assimp-utils, the loader many tools use), whole processes, paired:
#
#  1. loading: `bonescope inspect FILE --time 0.5` against `assimp info FILE` on the largest shared file of each
#     format, ProAnimationBank's locomotion set, and the generated glTF of benches/support/generated_gltf.rs (as
#     .glb and as .gltf with a base64 buffer), written into a temporary folder;
#  2. a library: the shared animation files (blender, bvh, fbx-proanimationbank, fbx-ufbx-data, gltf-khronos: the 34
#     that `bonescope scan` finds there) copied 50 times into a temporary folder, `bonescope scan DIR --jobs 2
#     --format jsonl` (the whole analysis of every clip) against `assimp info` on each of the same files through
#     `xargs -P2`, in files per second.
#
# Pairs are taken in rounds: each round runs hyperfine on both commands back to back (the order alternating
# between rounds), and the ratio is taken within the round, so a machine whose load changes (other builds) moves
# both sides. The tables give the medians over the rounds and the range of the ratio.
#
# Usage, from anywhere: benches/compare_assimp.sh [ROUNDS [RUNS]]   (default 5 rounds of 10 runs per command)
# Needs assimp and hyperfine (skips with a message without them) and ../shared/assets beside the repository. The
# release build goes to $CARGO_TARGET_DIR (default target/); BONESCOPE=path/to/bonescope measures that binary
# instead (another build, say) and builds only the generator.
set -euo pipefail
cd "$(dirname "$0")/.."

rounds=${1:-5}
runs=${2:-10}
for tool in assimp hyperfine; do
  if ! command -v "$tool" >/dev/null; then
    echo "skipped: \`$tool\` is not installed (Debian: apt-get install assimp-utils hyperfine)"
    exit 0
  fi
done
# shellcheck source=support/assets.sh
source benches/support/assets.sh
if [ -z "${BONESCOPE:-}" ]; then
  cargo build --quiet --release --locked --bin bonescope
  BONESCOPE=$target/release/bonescope
fi
cargo build --quiet --release --locked --example write_generated_gltf
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$target/release/examples/write_generated_gltf" "$work" >/dev/null

# `paired ROUNDS RUNS OPTIONS A B`: hyperfine (with OPTIONS) on commands A and B, RUNS runs each, in ROUNDS rounds
# whose order alternates; one line per round: "A_seconds B_seconds A/B" (means).
paired() {
  local count=$1 runs=$2 options=$3 a=$4 b=$5 csv="$work/round.csv" round first second
  for ((round = 0; round < count; round++)); do
    if ((round % 2 == 0)); then first=$a second=$b; else first=$b second=$a; fi
    # shellcheck disable=SC2086
    if ! hyperfine $options -w 1 -r "$runs" --style none --export-csv "$csv" "$first" "$second" >"$work/log" 2>&1; then
      cat "$work/log" >&2
      return 1
    fi
    awk -F, -v swap=$((round % 2)) 'NR == 2 { x = $2 } NR == 3 { y = $2 }
      END { a = swap ? y : x; b = swap ? x : y; printf "%.6f %.6f %.4f\n", a, b, a / b }' "$csv"
  done
}

# The median of the numbers on standard input.
median() {
  sort -g | awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'
}

# From paired's lines in FILE: the medians of A, B and the ratio, and the ratio's range ("A B ratio min max").
summary() {
  echo "$(cut -d' ' -f1 "$1" | median) $(cut -d' ' -f2 "$1" | median) $(cut -d' ' -f3 "$1" | median)" \
    "$(cut -d' ' -f3 "$1" | sort -g | sed -n '1p;$p' | paste -sd' ')"
}

echo "Loading: bonescope inspect FILE --time 0.5 against assimp info FILE ($rounds rounds of $runs runs each)"
printf '%-30s %12s %12s %8s %14s\n' file bonescope assimp ratio "ratio range"
for file in fbx-proanimationbank/skeleton.fbx fbx-proanimationbank/locomotions.fbx gltf-khronos/cesium_man.gltf \
  bvh/cmu_12_01_walk.bvh "$work/generated_200x6000.glb" "$work/generated_200x6000.gltf"; do
  path=$file
  [ -e "$path" ] || path=$assets/$file
  paired "$rounds" "$runs" -N "$BONESCOPE inspect $path --time 0.5" "assimp info $path" >"$work/rounds"
  read -r a b r lo hi < <(summary "$work/rounds")
  printf '%-30s %9.1f ms %9.1f ms %7.2fx %7.2f-%.2fx\n' "$(basename "$file")" \
    "$(awk "BEGIN { print $a * 1000 }")" "$(awk "BEGIN { print $b * 1000 }")" "$r" "$lo" "$hi"
done

library=$work/library
for copy in $(seq -w 1 50); do
  for folder in blender bvh fbx-proanimationbank fbx-ufbx-data gltf-khronos; do
    mkdir -p "$library/$copy/$folder"
    # The animation files and the buffers beside them (interpolation_test.gltf reads a .bin).
    find "$assets/$folder" -maxdepth 1 -type f \( -name '*.fbx' -o -name '*.glb' -o -name '*.gltf' -o -name '*.bvh' \
      -o -name '*.bin' \) -exec cp {} "$library/$copy/$folder/" \;
  done
done
count=$(find "$library" -type f ! -name '*.bin' | wc -l)
scanned=$("$BONESCOPE" scan "$library" --jobs 2 --format jsonl | wc -l)
echo
echo "Library: $count files (the shared animation files 50 times; bonescope scan finds $scanned), 3 rounds of 2 runs"
# assimp refuses two of the files (an FBX 6.1 ASCII and a 3ds Max 7 file: exit 3); -i keeps hyperfine going.
paired 3 2 -i "$BONESCOPE scan $library --jobs 2 --format jsonl" \
  "find $library -type f ! -name '*.bin' | xargs -P2 -n1 assimp info" >"$work/rounds"
read -r a b r lo hi < <(summary "$work/rounds")
printf 'bonescope scan --jobs 2:  %6.2f s  %6.0f files/s\n' "$a" "$(awk "BEGIN { print $count / $a }")"
printf 'assimp info, xargs -P2:   %6.2f s  %6.0f files/s\n' "$b" "$(awk "BEGIN { print $count / $b }")"
printf 'files/s, bonescope over assimp: %.2fx (rounds %.2f-%.2fx)\n' \
  "$(awk "BEGIN { print 1 / $r }")" "$(awk "BEGIN { print 1 / $hi }")" "$(awk "BEGIN { print 1 / $lo }")"
