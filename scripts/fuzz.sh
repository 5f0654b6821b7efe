#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fuzzes every reader a user can reach (fuzz/fuzz_*.cpp) with libFuzzer under ASan + UBSan, each for
# SECONDS seconds, starting from its seed corpus fuzz/corpus/<target>/, and writes a report.
#   scripts/fuzz.sh 1800                  every target, 30 minutes each
#   scripts/fuzz.sh 60 obj ply_binary     only these targets
#   FUZZ_JOBS=2 scripts/fuzz.sh 600       two targets at a time (default 1)
# Builds with clang (installs clang, libclang-rt-14-dev and libomp-14-dev when missing; the normal build
# does not need them) into build-fuzz/ (or $FUZZ_BUILD_DIR). What the runs leave there:
#   corpus/<target>/     the growing corpus (kept between runs; the seeds in fuzz/corpus/ are only read)
#   artifacts/<target>/  inputs that crashed (crash-*), leaked (leak-*), hung for 10 s (timeout-*) or
#                        needed more than 2 GB (oom-*)
#   logs/<target>.log    libFuzzer's output
#   fuzz-report.txt      per target: executions, exec/s, corpus size, findings (also printed)
# A finding does not stop the run. To fix one: reproduce it with build-fuzz/fuzz/fuzz_<target> FILE, fix the
# reader, and keep FILE as tests/fuzz_regressions/<target>/<name> (tests/test_fuzz_regressions.cpp replays it).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 1 ] || ! [[ $1 =~ ^[0-9]+$ ]]; then
  echo "usage: scripts/fuzz.sh SECONDS_PER_TARGET [TARGET...]" >&2
  exit 2
fi
seconds=$1
shift

bash scripts/deps.sh --fuzz

build=${FUZZ_BUILD_DIR:-build-fuzz}
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTRIVCON_FUZZ=ON -DTRIVCON_SANITIZE=ON \
  -DTRIVCON_BUILD_TESTS=OFF -DTRIVCON_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
nice -n 10 cmake --build "$build" --target fuzz_targets -j"$(nproc)"

all_targets=()
for f in fuzz/fuzz_*.cpp; do
  name=$(basename "$f" .cpp)
  all_targets+=("${name#fuzz_}")
done
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [ -x "$build/fuzz/fuzz_$t" ] || { echo "unknown fuzz target '$t' (have: ${all_targets[*]})" >&2; exit 2; }
done

# The longest input per target: a few times its largest seed, small enough to keep executions fast.
max_len() {
  case $1 in
    gz) echo 2048 ;;
    sing | sings | batch) echo 2048 ;;
    rawfield | field_ply) echo 8192 ;;
    *) echo 4096 ;;
  esac
}

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:symbolize=1:allocator_may_return_null=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1

run_target() {
  local t=$1
  local corpus="$build/corpus/$t" artifacts="$build/artifacts/$t" log="$build/logs/$t.log"
  mkdir -p "$corpus" "$artifacts" "$build/logs"
  local dict=()
  [ -f "fuzz/dict/$t.dict" ] && dict=(-dict="fuzz/dict/$t.dict")  # keywords of the format
  # -fork=1: the fuzzing runs in a child process that is restarted after a crash, leak or timeout, so a
  # finding is recorded (the -ignore_* flags) and the run goes on until the time is up.
  nice -n 10 "$build/fuzz/fuzz_$t" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -max_len="$(max_len "$t")" -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$artifacts/" "${dict[@]}" "$corpus" "fuzz/corpus/$t" >"$log" 2>&1 || true
}

jobs=${FUZZ_JOBS:-1}
echo "== fuzzing ${targets[*]}: ${seconds} s each, $jobs at a time (logs in $build/logs/)"
for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  echo "-- $t"
  run_target "$t" &
done
wait

report="$build/fuzz-report.txt"
{
  echo "trivcon fuzz report, $(date -u '+%Y-%m-%d %H:%M UTC'), ${seconds} s per target, commit $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
  printf '%-12s %12s %8s %8s %8s %6s %9s %5s  %s\n' target executions exec/s corpus crashes leaks timeouts ooms artifacts
  total=0
  for t in "${targets[@]}"; do
    log="$build/logs/$t.log"
    artifacts="$build/artifacts/$t"
    # The fork-mode status lines: "#EXECS: cov: C ft: F corp: N exec/s E oom/timeout/crash: a/b/c time: Ts ...".
    last=$(grep -E '^#[0-9]+: cov:' "$log" | tail -1 || true)
    execs=$(sed -E 's/^#([0-9]+):.*/\1/' <<<"$last")
    rate=$(sed -nE 's/.* exec\/s ([0-9]+) .*/\1/p' <<<"$last")
    corpus=$(find "$build/corpus/$t" -type f | wc -l)
    count() { find "$artifacts" -maxdepth 1 -type f -name "$1-*" | wc -l; }
    crashes=$(count crash) leaks=$(count leak) timeouts=$(count timeout) ooms=$(count oom)
    total=$((total + crashes + leaks + timeouts + ooms))
    printf '%-12s %12s %8s %8s %8s %6s %9s %5s  %s\n' "$t" "${execs:-?}" "${rate:-?}" "$corpus" "$crashes" "$leaks" "$timeouts" "$ooms" "$artifacts"
  done
  if [ "$total" -eq 0 ]; then
    echo "no findings"
  else
    echo "$total finding(s): reproduce with $build/fuzz/fuzz_<target> FILE; fix, then keep FILE in tests/fuzz_regressions/<target>/"
  fi
} | tee "$report"
echo "report: $report"
