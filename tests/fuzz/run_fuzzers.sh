#!/usr/bin/env bash
# Explores each libFuzzer target for a while, starting from a scratch copy of its committed corpus.
#   tests/fuzz/run_fuzzers.sh <fuzz build dir> [seconds per target, default 30] [target ...]
# FUZZ_SEED=<n> fixes libFuzzer's seed, so that a run explores the same inputs every time (CI does this: a red
# run must be reproducible; exploring with fresh seeds is what the long runs by hand are for).
# New inputs stay in the scratch dir (the committed corpus only grows by hand, with reproducers kept small);
# crashes, leaks, timeouts and OOMs are copied to <build dir>/fuzz-artifacts and fail the run.
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 <fuzz build dir> [seconds] [target ...]" >&2; exit 2; }
build=$(cd "$1" && pwd)
seconds=${2:-30}
shift $(( $# >= 2 ? 2 : 1 ))
here=$(cd "$(dirname "$0")" && pwd)
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for dir in "$here"/corpus/*/; do targets+=("$(basename "$dir")"); done
fi
# Leaks inside assimp itself are known and not ours (see the file); everything else must be clean.
export LSAN_OPTIONS="suppressions=$here/../robustness/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# fuzz_scene writes each input to a pose file: on a tmpfs that is memory speed, on a disk it is I/O-bound.
if [ -z "${TMPDIR:-}" ] && [ -d /dev/shm ] && [ -w /dev/shm ]; then export TMPDIR=/dev/shm; fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
artifacts="$build/fuzz-artifacts"
mkdir -p "$artifacts"
# One target's exploration; its summary line goes to $work/<target>.summary, the lines that tell a failure to
# $work/<target>.failure, the whole failure to the artifacts.
fuzz_one() {
  local target=$1 exe="$build/tests/fuzz/$1" log="$work/$1.log" result=ok
  if [ ! -x "$exe" ]; then
    echo "fuzz: $target: not built ($exe missing)" >"$work/$target.summary"
    return 1
  fi
  mkdir -p "$work/$target"
  local args=(-max_total_time="$seconds" -timeout=20 -rss_limit_mb=2560 -print_final_stats=1
              -artifact_prefix="$artifacts/$target-")
  [ -f "$here/$target.dict" ] && args+=(-dict="$here/$target.dict")
  [ -n "${FUZZ_SEED:-}" ] && args+=(-seed="$FUZZ_SEED")
  if ! "$exe" "${args[@]}" "$work/$target" "$here/corpus/$target" >"$log" 2>&1; then
    result=FAILED
    cp "$log" "$artifacts/$target.log"
    rm -rf "$artifacts/$target-corpus" && cp -r "$work/$target" "$artifacts/$target-corpus"
    grep -E "ERROR|SUMMARY|==[0-9]+==|broken|refusal|Test unit written" "$log" | head -40 \
      >"$work/$target.failure" || true
  fi
  local runs corpus
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  corpus=$(ls "$work/$target" | wc -l)
  echo "fuzz: $target: $result after ${seconds} s, ${runs:-?} executions, $corpus new corpus entries" \
    >"$work/$target.summary"
  [ "$result" = ok ]
}

# The targets run side by side, FUZZ_JOBS at a time (default: one per core); each is single-threaded.
jobs=${FUZZ_JOBS:-$(nproc 2>/dev/null || echo 1)}
status=0
running=0
for target in "${targets[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || status=1
    running=$((running - 1))
  fi
  fuzz_one "$target" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || status=1
  running=$((running - 1))
done
for target in "${targets[@]}"; do
  cat "$work/$target.summary"
  [ ! -f "$work/$target.failure" ] || cat "$work/$target.failure" >&2
done
exit $status
