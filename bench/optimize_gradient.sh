#!/usr/bin/env bash
# The gradient search against annealing on the §7.5 and §7.5.2 examples: whole-process wall time,
# the search's own time, evaluations and solves (`--timings`), the best value, and for the
# gradient search the solves it took to first reach annealing's best value (from its log).
#
#   bench/optimize_gradient.sh [RUNS] [PDESHAPE]      (default 3 runs, target/release/pdeshape)
set -euo pipefail
runs=${1:-3}
bin=${2:-target/release/pdeshape}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
for ex in optimize_curvature vesicle; do
  for method in anneal gradient; do
    for r in $(seq "$runs"); do
      start=$(date +%s.%N)
      "$bin" optimize "examples/$ex.toml" -o "$out/$ex-$method.toml" --method "$method" \
        --timings 2>"$out/t" >"$out/report"
      end=$(date +%s.%N)
      best=$(head -1 "$out/report" | sed 's/.*best \([0-9.e+-]*\).*/\1/')
      echo "$ex $method run $r: wall $(echo "$end - $start" | bc) s, $(grep '^{' "$out/t"), best $best"
    done
    cp "$out/$ex-$method.csv" "$out/$ex-$method.last.csv"
  done
  # The gradient search's solves until its value first reaches annealing's best: the search
  # re-run with its evaluations capped, the cap raised until the capped run reaches it (the
  # search is deterministic; the cap counts gradient evaluations, the rows of the log).
  target=$(awk -F, 'NR > 1 && ($5 < m || m == "") { m = $5 } END { print m }' "$out/$ex-anneal.last.csv")
  hit=$(awk -F, -v t="$target" 'NR > 1 && $5 <= t { print NR - 1; exit }' "$out/$ex-gradient.last.csv")
  reached=""
  for cap in $(seq "${hit:-1}" $(( ${hit:-1} + 20 ))); do
    [ -n "$hit" ] || break
    "$bin" optimize "examples/$ex.toml" -o "$out/cap.toml" --method gradient --evaluations "$cap" \
      --timings 2>"$out/t" >"$out/report"
    best=$(head -1 "$out/report" | sed 's/.*best \([0-9.e+-]*\).*/\1/')
    if awk -v b="$best" -v t="$target" 'BEGIN { exit !(b <= t) }'; then
      reached="best $best with --evaluations $cap: $(grep '^{' "$out/t")"
      break
    fi
  done
  echo "  annealing's best $target: the gradient search reaches it: ${reached:-not reached}"
done
