#!/usr/bin/env bash
# Annealing, the gradient search and the hybrid (annealing's chains, then the gradient search
# from each chain's best point) on §7.5's example, for a few seeds: the best value, the
# evaluations and design solves, and the search's own time (`--timings`), per run; then the
# medians per method.
#
#   bench/optimize_hybrid.sh [SEEDS] [PDESHAPE]    (default seeds "1 2 3", target/release/pdeshape)
set -euo pipefail
seeds=${1:-1 2 3}
bin=${2:-target/release/pdeshape}
ex=${EXAMPLE:-examples/optimize_curvature.toml}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "$(date -u '+%Y-%m-%d %H:%M:%S UTC'); load average: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
for method in anneal gradient hybrid; do
  for seed in $seeds; do
    "$bin" optimize "$ex" -o "$out/best.toml" --method "$method" --seed "$seed" \
      --timings 2>"$out/t" >"$out/report"
    best=$(head -1 "$out/report" | sed 's/.*best \([0-9.e+-]*\).*/\1/')
    t=$(grep '^{' "$out/t")
    ms=$(echo "$t" | sed 's/.*"search_ms":\([0-9.e+-]*\).*/\1/')
    solves=$(echo "$t" | sed 's/.*"solves":\([0-9]*\).*/\1/')
    evals=$(echo "$t" | sed 's/.*"evaluations":\([0-9]*\).*/\1/')
    echo "$method seed $seed: best $best, evaluations $evals, solves $solves, search_ms $ms"
    echo "$method $best $solves $ms" >>"$out/rows"
  done
done
median() { sort -g | awk '{ a[NR] = $1 } END { print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2 }'; }
for method in anneal gradient hybrid; do
  b=$(awk -v m="$method" '$1 == m { print $2 }' "$out/rows" | median)
  s=$(awk -v m="$method" '$1 == m { print $3 }' "$out/rows" | median)
  ms=$(awk -v m="$method" '$1 == m { print $4 }' "$out/rows" | median)
  echo "median $method: best $b, solves $s, search_ms $ms"
done
