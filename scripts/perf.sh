#!/usr/bin/env bash
# Regenerates the figures of docs/PERFORMANCE.md: the criterion benchmarks
# of every stage and of design -> verified G-code (examples and the scaling
# series), then peak memory per sample, docs/perf/scaling.csv and the plot
# docs/img/scaling.png. Takes 20–30 minutes on a 2-core machine.
#   scripts/perf.sh            # scaling series to 10M samples
#   MAX=1000000 scripts/perf.sh  # quicker: everything to 1M
set -euo pipefail
cd "$(dirname "$0")/.."
max="${MAX:-10000000}"
SWEEPCLAY_BENCH_MAX="$max" cargo bench -p sweepclay-core --bench pipeline
SWEEPCLAY_BENCH_MAX="$max" cargo bench -p sweepclay-plan --bench verified
cargo bench -p sweepclay-check --bench check
cargo run --release -p sweepclay-perf -- "$max"
