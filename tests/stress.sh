#!/usr/bin/env bash
# Stress check of the whole suite (not part of .ci/run): the README's test
# command from a fresh clone, RUNS times in a row with two CPU-bound
# processes beside it the whole time, then once more with ctest -j higher
# than the number of cores. Prints each run's result and wall time; exits
# non-zero if any run failed.
#
#   tests/stress.sh [RUNS (5)] [JOBS of the last run (2 x cores)]
set -uo pipefail
runs=${1:-5}
jobs=${2:-$(( 2 * $(nproc) ))}
repo=$(git -C "$(dirname "$0")/.." rev-parse --show-toplevel)
work=$(mktemp -d /tmp/stress.XXXXXX)
busy=()
stop_busy() { for pid in "${busy[@]}"; do kill "$pid" 2>/dev/null; done; }
trap stop_busy EXIT
for _ in 1 2; do
  sh -c 'while :; do :; done' &
  busy+=($!)
done
commit=$(git -C "$repo" rev-parse HEAD)  # every run tests this commit
echo "commit ${commit:0:7}, $(nproc) cores, 2 busy loops; logs in $work"

failed=0
one_run() {  # one_run NAME CTEST_JOBS
  local name=$1 ctest_jobs=$2 clone="$work/$1" started=$SECONDS status
  git clone -q "$repo" "$clone" && git -C "$clone" checkout -q "$commit"
  if [ "$ctest_jobs" = 2 ]; then  # exactly what CI runs
    (cd "$clone" && CI=true bash .ci/run) </dev/null >"$work/$name.log" 2>&1
  else                            # the same command with more ctest jobs
    (cd "$clone" && export CI=true && cmake -S . -B build -DRL_TESTS=ON && cmake --build build -j2 &&
       ctest --test-dir build -j"$ctest_jobs" --output-on-failure --no-tests=error -V) </dev/null >"$work/$name.log" 2>&1
  fi
  status=$?
  printf '%-12s ctest -j%-2s %s  %4d s\n' "$name" "$ctest_jobs" "$([ $status = 0 ] && echo pass || echo FAIL)" \
         $((SECONDS - started))
  [ $status = 0 ] || failed=1
  [ $status != 0 ] || rm -rf "$clone"   # keep a failed run's tree for a look
}
for n in $(seq 1 "$runs"); do one_run "run$n" 2; done
one_run "jobs$jobs" "$jobs"
exit $failed
