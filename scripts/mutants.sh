#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Mutation testing: a measure of the test suite's power (not part of CI; slow: every mutant rebuilds).
#
#   bash scripts/mutants.sh                 # every mutant of scripts/mutants.txt
#   bash scripts/mutants.sh ID...           # only these
#   bash scripts/mutants.sh --check         # only check that every mutant applies (no build)
#   bash scripts/mutants.sh --list          # list the ids
# Options: --jobs N (build and ctest parallelism, default 2), --no-baseline (skip the run of the unmutated
# copy's tests, which otherwise must pass for each regex before its mutants mean anything).
# Environment: TRIVCON_MUTANT_DIR (scratch folder, default ${TMPDIR:-/tmp}/trivcon-mutants-$USER),
# TRIVCON_MUTANTS_LIST (another list file).
#
# Each mutant (scripts/mutants.txt: id | file | exact original text | replacement | ctest regex) is applied
# to a COPY of the source tree in the scratch folder, never to this tree: the copy is built (Release, ccache
# when available, one build folder reused so only what the mutant touches is recompiled), the tests matching
# the regex run, and the mutant is KILLED when any of them fails, SURVIVED when all pass. The copy's file is
# restored after each mutant, and on exit or Ctrl-C (trap). A mutant whose original text does not occur
# exactly once is INVALID; one that does not compile is BUILD-FAILED (neither counts as killed).
set -uo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
list_file=${TRIVCON_MUTANTS_LIST:-$repo/scripts/mutants.txt}
scratch=${TRIVCON_MUTANT_DIR:-${TMPDIR:-/tmp}/trivcon-mutants-${USER:-$(id -un)}}
jobs=2
baseline=1
mode=run
ids=()
while [ $# -gt 0 ]; do
  case "$1" in
    --jobs) jobs=$2; shift 2 ;;
    --jobs=*) jobs=${1#--jobs=}; shift ;;
    --no-baseline) baseline=0; shift ;;
    --check) mode=check; shift ;;
    --list) mode=list; shift ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    -*) echo "mutants.sh: unknown option $1" >&2; exit 2 ;;
    *) ids+=("$1"); shift ;;
  esac
done

# --- Parse the mutant list: parallel arrays.
m_id=() m_file=() m_from=() m_to=() m_regex=()
line_no=0
while IFS= read -r line || [ -n "$line" ]; do
  line_no=$((line_no + 1))
  [[ -z "${line//[[:space:]]/}" || "$line" =~ ^[[:space:]]*# ]] && continue
  rest=$line fields=()
  while [[ "$rest" == *" | "* ]]; do fields+=("${rest%%" | "*}"); rest=${rest#*" | "}; done
  fields+=("$rest")
  if [ ${#fields[@]} -ne 5 ]; then
    echo "mutants.sh: $list_file:$line_no: expected 5 fields separated by ' | ', got ${#fields[@]}" >&2
    exit 2
  fi
  m_id+=("${fields[0]}") m_file+=("${fields[1]}") m_from+=("${fields[2]}") m_to+=("${fields[3]}") m_regex+=("${fields[4]}")
done < "$list_file"

if [ "$mode" = list ]; then
  printf '%s\n' "${m_id[@]}"
  exit 0
fi

# The selected mutants, in list order (unknown ids are an error).
selected=()
if [ ${#ids[@]} -eq 0 ]; then
  selected=("${!m_id[@]}")
else
  for want in "${ids[@]}"; do
    found=-1
    for i in "${!m_id[@]}"; do [ "${m_id[$i]}" = "$want" ] && found=$i; done
    if [ "$found" -lt 0 ]; then echo "mutants.sh: no mutant '$want' in $list_file" >&2; exit 2; fi
    selected+=("$found")
  done
fi

# Occurrences of the original text in a file (exact bytes), and the substitution of its one occurrence.
# The texts go through the environment so that no quoting can change them.
count_in() {  # file text
  FROM=$2 perl -0777 -ne '
    my ($n, $p) = (0, 0);
    while (($p = index($_, $ENV{FROM}, $p)) >= 0) { $n++; $p += length $ENV{FROM}; }
    print $n' "$1"
}
substitute() {  # file from to (exactly one occurrence, checked before)
  FROM=$2 TO=$3 perl -0777 -i -pe 'my $p = index($_, $ENV{FROM}); substr($_, $p, length $ENV{FROM}) = $ENV{TO} if $p >= 0' "$1"
}

if [ "$mode" = check ]; then
  bad=0
  for i in "${selected[@]}"; do
    f="$repo/${m_file[$i]}"
    n=$([ -f "$f" ] && count_in "$f" "${m_from[$i]}" || echo "missing")
    if [ "$n" = 1 ]; then
      printf '%-34s ok\n' "${m_id[$i]}"
    elif [ "$n" = missing ]; then
      printf '%-34s INVALID (no file %s)\n' "${m_id[$i]}" "${m_file[$i]}"
      bad=$((bad + 1))
    else
      printf '%-34s INVALID (original text found %s times in %s)\n' "${m_id[$i]}" "$n" "${m_file[$i]}"
      bad=$((bad + 1))
    fi
  done
  echo "${#selected[@]} mutants, $bad invalid"
  [ $bad -eq 0 ]
  exit
fi

# --- The scratch copy: sources without .git and build folders; mtimes kept so the build folder stays valid.
# The scratch folder must be one of ours: not /, not the repository, above or inside it, and either new, empty
# or marked by an earlier run (its src/ is deleted and rebuilt).
scratch=$(realpath -m "$scratch")
if [ "$scratch" = / ] || [[ "$repo/" == "$scratch/"* ]] || [[ "$scratch/" == "$repo/"* ]]; then
  echo "mutants.sh: refusing the scratch folder $scratch (it must be outside the repository and not contain it)" >&2
  exit 2
fi
if [ -d "$scratch" ] && [ -n "$(ls -A "$scratch")" ] && [ ! -e "$scratch/.trivcon-mutants" ]; then
  echo "mutants.sh: refusing the scratch folder $scratch: it is not empty and was not made by mutants.sh" >&2
  exit 2
fi
src="$scratch/src" build="$scratch/build" logs="$scratch/logs"
mkdir -p "$scratch" "$logs"
touch "$scratch/.trivcon-mutants"
rm -rf "$src"
mkdir -p "$src"
# -m: the copies get the current time, so the reused build folder recompiles every file (ccache hits
# where unchanged) and never keeps an object of an older copy whose file kept an older time.
tar -C "$repo" --exclude=./.git --exclude='./build*' --exclude=./demo-output -cf - . | tar -C "$src" -xmf -
# Tests look for the shared meshes next to the source tree (../shared/data/meshes).
if [ -d "$repo/../shared" ] && [ ! -e "$scratch/shared" ]; then ln -s "$(cd "$repo/../shared" && pwd)" "$scratch/shared"; fi

exec 3>&1 4>&2  # the traps print here: they may run while a build's output is redirected to its log
current_file="" current_backup="" child=""
# Builds and tests run as their own process group (setsid), so that an interrupt can stop all of them.
run_child() {
  setsid "$@" &
  child=$!
  wait "$child"
  local status=$?
  child=""
  return $status
}
restore() {
  if [ -n "$current_file" ] && [ -f "$current_backup" ]; then
    cp "$current_backup" "$current_file"
    touch "$current_file"  # newer than the mutant's object: the next build recompiles it (a ccache hit)
  fi
  current_file="" current_backup=""
}
summary_printed=0
declare -A result
print_summary() {
  [ $summary_printed = 1 ] && return
  summary_printed=1
  exec 1>&3 2>&4
  local killed=0 survived=0 other=0
  echo
  echo "== summary"
  for i in "${selected[@]}"; do
    local r=${result[$i]:-NOT-RUN}
    printf '%-34s %s\n' "${m_id[$i]}" "$r"
    case "$r" in KILLED*) killed=$((killed + 1)) ;; SURVIVED*) survived=$((survived + 1)) ;; *) other=$((other + 1)) ;; esac
  done
  local scored=$((killed + survived))
  echo "killed $killed, survived $survived, other $other (invalid, build failed, baseline failing or not run)"
  [ $scored -gt 0 ] && echo "mutation score $((100 * killed / scored))% of $scored"
}
on_exit() { restore; print_summary; }
on_signal() {
  exec 1>&3 2>&4
  echo
  echo "mutants.sh: interrupted, restoring the scratch copy" >&2
  trap - EXIT
  if [ -n "$child" ]; then
    kill -TERM -- "-$child" 2> /dev/null
    wait "$child" 2> /dev/null
  fi
  restore
  print_summary
  exit 130
}
trap on_exit EXIT
trap on_signal INT TERM

launcher=()
command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
echo "scratch copy: $src; build: $build; logs: $logs"
if ! cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release -DTRIVCON_BUILD_BENCH=OFF "${launcher[@]}" > "$logs/configure.log" 2>&1; then
  echo "mutants.sh: cmake configure failed, see $logs/configure.log" >&2
  exit 1
fi

build_copy() { run_child cmake --build "$build" -j "$jobs" > "$1" 2>&1; }
run_tests() {  # regex log → ctest's status (0: all passed)
  run_child ctest --test-dir "$build" -R "$1" -j "$jobs" --no-tests=error --timeout 900 --output-on-failure > "$2" 2>&1
}
tests_run() { sed -nE 's/.* tests? failed out of ([0-9]+).*/\1/p' "$1" | tail -1; }
no_tests() { grep -q "No tests were found" "$1"; }
failed_tests() {  # the first few names under ctest's "The following tests FAILED:" (not the skipped ones)
  awk '/The following tests FAILED:/ { f = 1; next } f && /^[ \t]+[0-9]+ - / { print $3 }' "$1" | head -5 | paste -sd, -
}

# --- Baseline: the unmutated copy must build and pass each regex's tests, or its mutants prove nothing.
declare -A baseline_ok
if [ $baseline = 1 ]; then
  echo "baseline: building the unmutated copy"
  if ! build_copy "$logs/baseline-build.log"; then
    echo "mutants.sh: the unmutated copy does not build, see $logs/baseline-build.log" >&2
    exit 1
  fi
  for i in "${selected[@]}"; do
    r=${m_regex[$i]}
    [ -n "${baseline_ok[$r]+x}" ] && continue
    b="$logs/baseline-$i.log"
    if run_tests "$r" "$b"; then baseline_ok[$r]=1; else baseline_ok[$r]=0; fi
    if [ "${baseline_ok[$r]}" = 1 ]; then
      echo "baseline $r: $(tests_run "$b") tests pass"
    elif no_tests "$b"; then
      echo "baseline $r: NO TESTS match the regex"
    else
      echo "baseline $r: FAILS ($(failed_tests "$b"))"
    fi
  done
fi

# --- The mutants.
for i in "${selected[@]}"; do
  id=${m_id[$i]} file="$src/${m_file[$i]}" log="$logs/${m_id[$i]}.log"
  if [ $baseline = 1 ] && [ "${baseline_ok[${m_regex[$i]}]}" != 1 ]; then
    result[$i]="BASELINE-FAILS (the regex's tests fail without the mutant)"
    printf '%-34s %s\n' "$id" "${result[$i]}"
    continue
  fi
  n=$([ -f "$file" ] && count_in "$file" "${m_from[$i]}" || echo "missing")
  if [ "$n" != 1 ]; then
    if [ "$n" = missing ]; then
      result[$i]="INVALID (no file ${m_file[$i]})"
    else
      result[$i]="INVALID (original text found $n times in ${m_file[$i]})"
    fi
    printf '%-34s %s\n' "$id" "${result[$i]}"
    continue
  fi
  current_file=$file current_backup="$scratch/backup"
  cp "$file" "$current_backup"
  substitute "$file" "${m_from[$i]}" "${m_to[$i]}"
  touch "$file"
  start=$(date +%s)
  if ! build_copy "$log"; then
    result[$i]="BUILD-FAILED (see $log)"
  elif run_tests "${m_regex[$i]}" "$log.tests"; then
    result[$i]="SURVIVED ($(tests_run "$log.tests") tests pass)"
  elif no_tests "$log.tests"; then
    result[$i]="NO-TESTS (the regex matches no test)"
  else
    result[$i]="KILLED by $(failed_tests "$log.tests")"
  fi
  restore
  printf '%-34s %s (%ss)\n' "$id" "${result[$i]}" "$(($(date +%s) - start))"
done
