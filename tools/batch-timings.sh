#!/usr/bin/env bash
# The batch timings of docs/PERFORMANCE.md: a class of 14 generated submissions (the solution, the
# starter, each checkpoint stubbed alone, six catalogue mistakes) graded by `grader batch` with a
# cold work folder, then each submission's phases from its report. Run by hand from the
# repository's root (about 8 minutes on 2 cores): tools/batch-timings.sh [OUT]
set -euo pipefail
out="${1:-target/batch-timings}"
class="$out/class"
rm -rf "$out"
mkdir -p "$class"
cargo build --quiet --release --package raylab-grade --bin grader
grader=target/release/grader
git ls-files -z | (mkdir -p "$class/00-solution" && xargs -0 cp --parents -t "$class/00-solution")
cargo xtask starter --out "$class/01-starter" > /dev/null
for n in 2 3 4 5 6 7; do
    "$grader" make-variant "stub_$n" --out "$class/1$n-stub_$n" > /dev/null
done
for name in triangle_rejects_back_faces aabb_open_interval bvh_first_hit_not_closest \
    refraction_no_total_internal_reflection no_shadows no_antialiasing; do
    "$grader" make-variant "$name" --out "$class/2-$name" > /dev/null
done
start=$(date +%s)
"$grader" batch "$class" --out "$out/grades"
echo "batch: $(( $(date +%s) - start )) s for $(ls "$class" | wc -l) submissions"
for report in "$out"/grades/*/report.txt; do
    printf '%-45s %s\n' "$(basename "$(dirname "$report")")" "$(grep '^total:' "$report")"
done
