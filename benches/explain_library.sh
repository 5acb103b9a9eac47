#!/usr/bin/env bash
# `scan --explain` against `scan` on the shared assets (every file `scan` finds under ../shared/assets), whole
# processes: the time the explanations add to a library scan, each stretched bone's main cause and best fix.
#
# The two commands run alternately, ROUNDS times each (default 9), so a machine whose load changes moves both; the
# line printed gives the median wall time of each and the median of the per-round ratios, with their range.
#
# Usage, from anywhere: benches/explain_library.sh [ROUNDS] [FILE|FOLDER...]: the shared assets by default, or
# what is named (paths from the repository's root), e.g. a generated rig the explanations were not tuned on:
#   cargo run --release --locked --example write_generated_gltf -- target/generated
#   benches/explain_library.sh 9 target/generated/generated_sixth_200x6000.glb
# The release build of the command line goes to $CARGO_TARGET_DIR (default target/); BONESCOPE=path/to/bonescope
# measures that binary instead.
set -euo pipefail
cd "$(dirname "$0")/.."

rounds=${1:-9}
# shellcheck source=support/assets.sh
source benches/support/assets.sh
scanned=("${@:2}")
[ ${#scanned[@]} -gt 0 ] || scanned=("$assets")
if [ -z "${BONESCOPE:-}" ]; then
  cargo build --quiet --release --locked --no-default-features --bin bonescope
  BONESCOPE=$target/release/bonescope
fi

# Seconds one run of `bonescope scan ASSETS --format jsonl` with the extra options "$@" takes.
seconds() {
  local start end
  start=$(date +%s.%N)
  "$BONESCOPE" scan "${scanned[@]}" --format jsonl "$@" >/dev/null 2>&1 || true
  end=$(date +%s.%N)
  awk "BEGIN { print $end - $start }"
}

median() {
  sort -g | awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'
}

# Some shared files are refused on purpose (scan then exits 2): the counts do not mind.
files=$({ "$BONESCOPE" scan "${scanned[@]}" --format jsonl 2>/dev/null || true; } | wc -l)
explained=$({ "$BONESCOPE" scan "${scanned[@]}" --explain --format jsonl 2>/dev/null || true; } | grep -c '"explained"' || true)
plain=() explaining=() ratios=()
for ((round = 0; round < rounds; round++)); do
  if ((round % 2 == 0)); then
    a=$(seconds); b=$(seconds --explain)
  else
    b=$(seconds --explain); a=$(seconds)
  fi
  plain+=("$a") explaining+=("$b") ratios+=("$(awk "BEGIN { print $b / $a }")")
done
range=$(printf '%s\n' "${ratios[@]}" | sort -g | sed -n '1p;$p' | paste -sd' ')
printf '%s files (%s with explanations), %s rounds: scan %.3f s, scan --explain %.3f s, ratio %.2fx (%s)\n' \
  "$files" "$explained" "$rounds" "$(printf '%s\n' "${plain[@]}" | median)" \
  "$(printf '%s\n' "${explaining[@]}" | median)" "$(printf '%s\n' "${ratios[@]}" | median)" "$range"
