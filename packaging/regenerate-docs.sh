#!/usr/bin/env bash
# Reruns every measurement behind a figure in docs/ and rewrites the pages (issue 41).
#
#   packaging/regenerate-docs.sh                 every page: builds, then each step in turn (hours)
#   packaging/regenerate-docs.sh --only PAGE[,PAGE...]   those pages (names as --list gives them)
#   packaging/regenerate-docs.sh --list          the pages, their commands and how long each takes
#   packaging/regenerate-docs.sh --quick         every step at tiny sizes and durations, into a
#                                                scratch copy of docs/ (build/regenerate-docs-quick/
#                                                docs, or --output-dir DIR): the script end to end
#
# It installs what is missing (packaging/setup-debian.sh --measuring: also valgrind for the
# instruction counts and LLVM's coverage tools), builds the release preset (the fuzzing and
# sanitizers steps build their presets), then runs the measurements one after another, never two
# at once: they time the machine, so run it on a quiet one. Each regenerated page gets one line
# under its title, from measured_line below: the commit, the date, the machine and the commands.
# A page is rewritten in one of three ways: written whole by its command (liversim-cli bench and
# the other writers); a block between "<!-- begin NAME -->" and "<!-- end NAME -->" lines
# replaced by what the commands wrote (the text around it is the page's own); or a figure followed
# by "<!-- fig:KEY -->" replaced by the value of KEY (a test's recorded property, a coverage
# figure). A step that fails stops there (pages it had not rewritten yet stay as they were); the
# next steps go on, and the script exits 1 naming it.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

usage() {
  sed -n '2,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}

only=""
quick=0
listing=0
out=""
while (($#)); do
  case $1 in
    --only) only=${2:?--only needs a list of pages}; shift 2 ;;
    --only=*) only=${1#*=}; shift ;;
    --quick) quick=1; shift ;;
    --list) listing=1; shift ;;
    --output-dir) out=${2:?--output-dir needs a folder}; shift 2 ;;
    -h | --help) usage; exit 0 ;;
    *) echo "regenerate-docs: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
done

# ---- The steps, in the order they run ---------------------------------------------------------
# Each is a function step_NAME. A line a step: its name | the pages it rewrites (under docs/) | its
# expected minutes on a quiet 2-core machine, the full run (estimated from the wall times the pages
# recorded) and --quick (builds not counted) | what takes the time.
step_table=(
  "architecture|architecture.md|1|1|"
  "mesh-quality|mesh-quality.md|2|1|"
  "material-verification|material-verification.md|1|1|"
  "tissue-model|tissue-model.md|1|1|"
  "viscous-tissue|viscous-tissue.md|1|1|"
  "haptics|haptics.md|1|1|"
  "session-storage|session-storage.md|1|1|"
  "seed-experiments|seed-experiments.md|4|1|"
  "performance|performance.md|10|2|valgrind counts instructions; the workstation runs under Xvfb for its memory"
  "cutting|cutting-performance.md cutting.md|5|1|eight strokes at 10583 tets"
  "cutting-live|cutting-live.md|1|1|"
  "haptics-servo|haptics-servo.md|1|1|"
  "rendering-performance|rendering-performance.md|3|1|"
  "accuracy-study|accuracy-study.md accuracy-study-effects/accuracy-study.md|20|1|both studies and their plots; references at 1/64 of the smallest step"
  "integrators|integrators.md|1|1|its table from the elastic study's CSV: run after accuracy-study"
  "stability-report|stability-report.md|6|1|ten simulated minutes of a free liver among the cases"
  "soak|soak.md|32|2|a 30-minute recorded session"
  "training-centre-load|training-centre-load.md|12|2|a 10-minute recorded session, then 20 uploads to a throwaway PostgreSQL"
  "fuzzing|fuzzing.md|90|10|six 10-minute long runs, a fresh fuzz build timed, a coverage build"
  "sanitizers|sanitizers.md|120|15|the asan preset's build of every target (about an hour) and its whole suite; the tsan-threads and asan-inputs steps"
  "ci|ci.md|60|1|.ci/run on a clean clone twice: with the compiler cache as it is, and without it (a new machine's builds)"
)
steps=()
declare -A pages=() minutes_of=() step_notes=()
for entry in "${step_table[@]}"; do
  IFS='|' read -r step step_pages full fast note <<<"$entry"
  steps+=("$step")
  pages[$step]=$step_pages
  minutes_of[$step]="$full $fast"
  step_notes[$step]=$note
done

# The steps asked for: all, or those --only names (a step or one of its pages, .md optional).
selected=()
if [ -z "$only" ]; then
  selected=("${steps[@]}")
else
  IFS=, read -r -a wanted <<<"$only"
  for name in "${wanted[@]}"; do
    name=${name#docs/}
    name=${name%.md}
    found=0
    for step in "${steps[@]}"; do
      for page in $step ${pages[$step]}; do
        if [ "$name" = "${page%.md}" ]; then
          found=1
          [[ " ${selected[*]} " == *" $step "* ]] || selected+=("$step")
        fi
      done
    done
    ((found)) || { echo "regenerate-docs: no page '$name' (--list lists them)" >&2; exit 2; }
  done
  ordered=()
  for step in "${steps[@]}"; do [[ " ${selected[*]} " != *" $step "* ]] || ordered+=("$step"); done
  selected=("${ordered[@]}")
fi

# ---- Where things go ----------------------------------------------------------------------------
if ((quick)); then
  work=build/regenerate-docs-quick
  out=${out:-$work/docs}
else
  work=build/regenerate-docs
  out=${out:-docs}
fi
build=build/release
cli=$build/app/liversim-cli
shared=../shared/data
zhang=("$shared/external/zhang-liver/Liver_Iso.inp" --fixed-set 'FixT&P')
# -noreset: otherwise the server resets whenever its last client leaves, and a test connecting
# then is refused ("could not connect to display" in one CI run, two GUI tests in parallel).
xvfb=(xvfb-run -a -s "-screen 0 1280x1024x24 -noreset")
jobs=$(nproc)

# The commit and the machine, taken once before anything is written (a page this run rewrites is
# not a change of the code it measures).
commit=$(git rev-parse --short HEAD)
[ -z "$(git status --porcelain)" ] || commit+=" + uncommitted changes"
cpu=$(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -n 1)
cores=$(grep -c '^processor' /proc/cpuinfo)
ram_gib=$(awk '/^MemTotal/ { printf "%.0f", $2 / 1048576 }' /proc/meminfo)

# The line under a regenerated page's title, from the commands of its step: the one place its
# format is written.
measured_line() { # COMMAND...
  local shown="" c
  if (($# <= 3)); then
    for c in "$@"; do shown+="${shown:+; }\`$c\`"; done
  else
    shown="\`packaging/regenerate-docs.sh --only $step\`, whose $# commands are shown with what they measured"
  fi
  echo "Measured at commit $commit on $(date -u +%Y-%m-%d), $cpu ($cores cores, $ram_gib GiB)," \
    "by \`packaging/regenerate-docs.sh\` (this page: $shown)."
}

# ---- Running a step's commands ------------------------------------------------------------------
step=""
log=/dev/null
commands=() # the step's commands as the pages show them, in the order run

# A command as a page shows it: liversim-cli for the built one, paths from the top of the tree,
# xvfb-run without its screen, quotes where an argument needs them.
shown() {
  local text="" a
  for a in "$@"; do
    if [ "$a" = "${xvfb[3]}" ]; then
      text=${text% -s}
      continue
    fi
    a=${a//$cli/liversim-cli}
    a=${a//$root\//}
    if [[ $a =~ ^[A-Za-z0-9_./,:=+@%^-]+$ ]]; then
      text+=" $a"
    else
      text+=" '${a//\'/\'\\\'\'}'"
    fi
  done
  echo "${text# }"
}

# run [--stdout FILE | --output FILE] [--may-fail] COMMAND...: runs a command of the step (with
# --list only prints it), its output into the step's log, and its stdout (--stdout) or stdout and
# stderr (--output) also into FILE. A failure ends the step unless --may-fail, which returns the
# command's exit code instead.
run() {
  local file="" both=0 may_fail=0 status=0
  while :; do
    case $1 in
      --stdout) file=$2; shift 2 ;;
      --output) file=$2; both=1; shift 2 ;;
      --may-fail) may_fail=1; shift ;;
      *) break ;;
    esac
  done
  commands+=("$(shown "$@")")
  if ((listing)); then
    echo "    ${commands[-1]}"
    return 0
  fi
  echo "  \$ ${commands[-1]}"
  # shellcheck disable=SC2094 # both append to the log, neither reads it
  if ((both)); then
    { "$@" 2>&1 | tee -a "$log" >"$file"; } || status=$?
  elif [ -n "$file" ]; then
    { "$@" 2>>"$log" | tee -a "$log" >"$file"; } || status=$?
  else
    "$@" >>"$log" 2>&1 || status=$?
  fi
  if ((status != 0)); then
    ((may_fail)) && return "$status"
    echo "  failed with exit code $status; the end of $log:" >&2
    tail -n 20 "$log" >&2
    return "$status"
  fi
}
run_x() { run "${xvfb[@]}" "$@"; } # a command that renders
doing() { ((!listing)); }           # false with --list: a step returns before rewriting pages

# ---- Rewriting pages ----------------------------------------------------------------------------
# Puts measured_line of the step's commands (FROM to TO - 1 when given) under the page's title, in
# place of the line a writer put there ("Written by `...`") or of an earlier one.
stamp() { # PAGE [FROM TO]
  local from=${2:-0} to=${3:-${#commands[@]}}
  python3 - "$out/$1" "$(measured_line "${commands[@]:from:to-from}")" <<'PYTHON'
import sys
path, line = sys.argv[1], sys.argv[2]
lines = open(path, encoding="utf-8").read().split("\n")
title = next(i for i, l in enumerate(lines) if l.startswith("# "))
end = next((i for i, l in enumerate(lines) if i > title and l.startswith("## ")), len(lines))
for i in range(title + 1, end):
    if lines[i].startswith(("Measured at commit ", "Written by `")):
        lines[i] = line
        break
else:
    lines[title + 1:title + 1] = ["", line]
open(path, "w", encoding="utf-8").write("\n".join(lines))
PYTHON
}

# Replaces the lines between "<!-- begin NAME -->" and "<!-- end NAME -->" of the page with the
# file's text, after the step's commands FROM to TO - 1 ("`command`; `command`:") when given.
splice() { # PAGE NAME FILE [FROM TO]
  local head="" c
  if [ $# -ge 5 ]; then
    for c in "${commands[@]:$4:$5-$4}"; do head+="${head:+; }\`$c\`"; done
    head+=":"
  fi
  python3 - "$out/$1" "$2" "$3" "$head" <<'PYTHON'
import sys
path, name, source, head = sys.argv[1:5]
text = open(path, encoding="utf-8").read()
begin, end = f"<!-- begin {name} -->\n", f"<!-- end {name} -->"
if begin not in text or end not in text:
    sys.exit(f"regenerate-docs: {path} has no block '{name}'")
body = open(source, encoding="utf-8").read().rstrip("\n") + "\n"
if head:
    body = head + "\n\n" + body
before, rest = text.split(begin, 1)
_, after = rest.split(end, 1)
open(path, "w", encoding="utf-8").write(before + begin + body + end + after)
PYTHON
}

# Replaces each figure followed by "<!-- fig:KEY -->" (the figure: the characters before it up to
# a space or a table's bar) with KEY's value in the file of "KEY<TAB>VALUE" lines; a key the file
# lacks is an error naming it.
fill() { # PAGE VALUES
  python3 - "$out/$1" "$2" <<'PYTHON'
import re, sys
path, values_file = sys.argv[1:3]
values = dict(l.rstrip("\n").split("\t", 1) for l in open(values_file, encoding="utf-8") if "\t" in l)
text = open(path, encoding="utf-8").read()
missing = []
def value(match):
    if match.group(2) not in values:
        missing.append(match.group(2))
        return match.group(0)
    return values[match.group(2)] + match.group(0)[len(match.group(1)):]
text = re.sub(r"([^\s|]*)<!-- fig:(\S+) -->", value, text)
if missing:
    sys.exit(f"regenerate-docs: {path}: no value for " + ", ".join(sorted(set(missing))))
open(path, "w", encoding="utf-8").write(text)
PYTHON
}

# The properties GoogleTest recorded (RecordProperty) in a --gtest_output=json file, as
# "Suite.Test/property<TAB>value" lines; and "run/tests", "run/milliseconds": how many tests ran
# and in how long.
gtest_properties() { # JSON
  python3 - "$1" <<'PYTHON'
import json, sys
standard = {"name", "status", "result", "timestamp", "time", "classname", "failures", "file", "line"}
report = json.load(open(sys.argv[1]))
print(f"run/tests\t{report['tests']}")
print(f"run/milliseconds\t{float(report['time'].rstrip('s')) * 1e3:.0f}")
for suite in report["testsuites"]:
    for test in suite["testsuite"]:
        for key, value in test.items():
            if key not in standard:
                print(f"{suite['name']}.{test['name']}/{key}\t{value}")
PYTHON
}

# A file of command output as a fenced block.
fenced() { # FILE
  echo '```'
  grep -v '^wrote ' "$1"
  echo '```'
}

# ---- The steps ----------------------------------------------------------------------------------
# Each runs its commands with run, all of them before `doing || return 0` (so that --list sees
# them), then rewrites its pages. $w is the step's scratch folder, $out the pages' folder.

step_mesh-quality() {
  local sizes=(3841 5406 7312 9371 10583) targets=(3000 10000) sim_time=2 n surfaces skeleton
  ((!quick)) || { sizes=(1000 2000) targets=(1000) sim_time=0.05; }
  ((listing)) || rm -f "$w/builtin.md" "$w/surface.md"
  for n in "${sizes[@]}"; do run "$cli" mesh-report --tets "$n" --table "$w/builtin.md"; done
  run "$cli" mesh-report --mesh "${zhang[@]}" --table "$w/builtin.md" \
    --write-surface "$w/zhang-liver-boundary.obj"
  surfaces=${#commands[@]}
  for n in "${targets[@]}"; do
    run "$cli" mesh-report --surface "$w/zhang-liver-boundary.obj" --length-unit mm --tets "$n" \
      --table "$w/surface.md"
  done
  skeleton=${#commands[@]}
  run --stdout "$w/skeleton.txt" "$cli" simulate --time "$sim_time" --force 0 0.1 0
  doing || return 0
  fenced "$w/skeleton.txt" >"$w/skeleton.md"
  splice mesh-quality.md builtin-meshes "$w/builtin.md" 0 "$surfaces"
  splice mesh-quality.md surface-meshes "$w/surface.md" "$surfaces" "$skeleton"
  splice mesh-quality.md skeleton-speed "$w/skeleton.md" "$skeleton" "${#commands[@]}"
  stamp mesh-quality.md
}

step_material-verification() {
  local duration=10 mode smaller half
  ((!quick)) || duration=1
  ((listing)) || { rm -f "$w"/*.md; mkdir -p "$out/images"; }
  for mode in relaxation creep yield-creep; do
    run_x "$cli" material-test "$mode" --duration "$duration" \
      --plot "$out/images/material-test-$mode.png" --table "$w/defaults.md"
  done
  smaller=${#commands[@]}
  run "$cli" material-test relaxation --duration "$duration" --strain 1e-4 --table "$w/smaller.md"
  run "$cli" material-test creep --duration "$duration" --stress 0.1 --table "$w/smaller.md"
  half=${#commands[@]}
  for mode in relaxation creep yield-creep; do
    run "$cli" material-test "$mode" --duration "$duration" --dt 0.005 --table "$w/half-step.md"
  done
  doing || return 0
  splice material-verification.md defaults "$w/defaults.md" 0 "$smaller"
  splice material-verification.md smaller-load "$w/smaller.md" "$smaller" "$half"
  splice material-verification.md half-step "$w/half-step.md" "$half" "${#commands[@]}"
  stamp material-verification.md
}

# A page whose figures are properties the tests of the filter record: runs them (--gtest_output),
# fills the page's figures and puts the line under its title.
gtest_figures() { # PAGE FILTER
  run "$build/tests/liversim_core_tests" --gtest_filter="$2" --gtest_output="json:$w/tests.json"
  doing || return 0
  gtest_properties "$w/tests.json" >"$w/figures.tsv"
  fill "$1" "$w/figures.tsv"
  stamp "$1"
}
step_tissue-model() { gtest_figures tissue-model.md 'Locking.*'; }
step_viscous-tissue() { gtest_figures viscous-tissue.md 'ViscousTissue.*'; }

step_haptics() {
  local runs=3 r
  ((!quick)) || runs=1
  for ((r = 1; r <= runs; ++r)); do
    run --stdout "$w/run-$r.txt" "$build/tests/liversim_threads_tests" \
      --gtest_filter='ServoLoop.Runs*:HapticCoupling*'
  done
  doing || return 0
  for ((r = 1; r <= runs; ++r)); do
    grep -E '^(servo|energy into the hand):' "$w/run-$r.txt" | sed "s/^/run $r: /"
  done >"$w/servo.txt"
  fenced "$w/servo.txt" >"$w/servo.md"
  splice haptics.md servo-test-runs "$w/servo.md" 0 "${#commands[@]}"
  stamp haptics.md
}

step_session-storage() {
  run --stdout "$w/killed.txt" "$build/tests/storage/liversim_storage_tests" \
    --gtest_filter='*Killed*'
  doing || return 0
  grep '^killed at' "$w/killed.txt" >"$w/killed-line.txt"
  fenced "$w/killed-line.txt" >"$w/killed.md"
  splice session-storage.md killed-writer "$w/killed.md" 0 1
  stamp session-storage.md
}

step_seed-experiments() {
  local tets=() creep=() long_creep=(--duration 8) pull=() timing=() marks=()
  if ((quick)); then
    tets=(--tets 1000) creep=(--ramp-time 0.1 --duration 0.2) long_creep=("${creep[@]}")
    pull=(--forces 0.93 --tolerance 1e-2) timing=(--tets "1000,2000" --time 0.02)
  fi
  ((listing)) || mkdir -p "$out/images"
  marks+=(${#commands[@]})
  run_x "$cli" experiment creep "${tets[@]}" "${creep[@]}" --csv "$w/creep.csv" \
    --ratio-csv "$w/creep-ratio.csv" --plot "$out/images/seed-creep.png" \
    --ratio-plot "$out/images/seed-creep-ratio.png" --table "$w/creep.md"
  marks+=(${#commands[@]})
  run "$cli" experiment pull "${tets[@]}" --forces 0.63 --table "$w/creep-reference.md"
  marks+=(${#commands[@]})
  run_x "$cli" experiment creep "${tets[@]}" --viscoelastic "${long_creep[@]}" \
    --plot "$out/images/seed-creep-viscoelastic.png" --table "$w/creep-viscoelastic.md"
  marks+=(${#commands[@]})
  run_x "$cli" experiment pull "${tets[@]}" "${pull[@]}" --csv "$w/pull.csv" \
    --history-csv "$w/pull-history.csv" --plot "$out/images/seed-pull.png" --table "$w/pull.md"
  marks+=(${#commands[@]})
  run "$cli" experiment pull "${tets[@]}" "${pull[@]}" --attachment forceps \
    --table "$w/pull-forceps.md"
  marks+=(${#commands[@]})
  run_x "$cli" experiment timing "${timing[@]}" --csv "$w/timing.csv" \
    --plot "$out/images/seed-timing.png" --table "$w/timing.md"
  marks+=(${#commands[@]})
  run "$cli" experiment timing "${timing[@]}" --integrator rk4 --csv "$w/timing-rk4.csv" \
    --table "$w/timing-rk4.md"
  doing || return 0
  splice seed-experiments.md creep "$w/creep.md" "${marks[0]}" $((marks[0] + 1))
  splice seed-experiments.md creep-reference "$w/creep-reference.md" "${marks[1]}" $((marks[1] + 1))
  splice seed-experiments.md creep-viscoelastic "$w/creep-viscoelastic.md" "${marks[2]}" \
    $((marks[2] + 1))
  splice seed-experiments.md pull "$w/pull.md" "${marks[3]}" $((marks[3] + 1))
  splice seed-experiments.md pull-forceps "$w/pull-forceps.md" "${marks[4]}" $((marks[4] + 1))
  splice seed-experiments.md timing "$w/timing.md" "${marks[5]}" $((marks[5] + 1))
  splice seed-experiments.md timing-rk4 "$w/timing-rk4.md" "${marks[6]}" $((marks[6] + 1))
  stamp seed-experiments.md
}

step_performance() {
  local args=(--tets "3841,5406,7312,9371,10583" --stepping-tets "5406,10583" --threads 2
    --min-time 0.3 --table1-seconds 1 --workstation-tets 10583 --workstation-seconds 10)
  ((!quick)) || args=(--tets 1000 --stepping-tets 1000 --threads 2 --min-time 0.01
    --table1-seconds 0.01 --workstation-tets 1000 --workstation-seconds 1)
  # Under Xvfb: the workstation whose memory the bench measures needs an OpenGL display (Qt's
  # offscreen platform has no OpenGL widget: the workstation refuses to start on it).
  run "${xvfb[@]}" "$cli" bench "${args[@]}" --output-dir "$out"
  doing || return 0
  stamp performance.md
}

# cutting-performance.md; and in cutting.md, more runs of the same stroke: the same command twice
# more, three single repeats, two on one thread.
# One run of the shipped scripted strokes through the workstation's own loop (issue 42): what a
# trainee's cut meets, second by second; --quick on the 1500-tet liver.
step_cutting-live() {
  local tets=5406
  ((!quick)) || tets=1500
  run "$cli" bench-cut --live --trajectory tests/data/trajectories/free-practice-three-strokes.txt \
    --tets "$tets" --output-dir "$out"
  # The shipped wedge resection (its own liver) with both hands, the scripted resection that
  # frees the tumour (issue 42), as a section of the same page.
  ((listing)) || mkdir -p "$w/wedge"
  run "$cli" bench-cut --live --trajectory tests/data/trajectories/wedge-resection-right-hand.txt \
    --left-trajectory tests/data/trajectories/wedge-resection-left-hand.txt --left-tool forceps \
    --scenario scenarios/wedge-resection-peripheral-tumour.json --output-dir "$w/wedge"
  doing || return 0
  python3 - "$out/cutting-live.md" "$w/wedge/cutting-live.md" "${commands[1]}" <<'PYTHON'
import sys
page, section, command = sys.argv[1:4]
body = open(section, encoding="utf-8").read().split("\n")
# The section's text after its title and the line naming its command.
body = [l for l in body[1:] if not l.startswith("Written by `")]
while body and not body[0].strip():
    body.pop(0)
text = open(page, encoding="utf-8").read().rstrip("\n")
text += "\n\n## The shipped wedge resection, both hands\n\nThis section: `" + command + "`.\n\n"
text += "\n".join(body).rstrip("\n") + "\n"
open(page, "w", encoding="utf-8").write(text)
PYTHON
  stamp cutting-live.md
}

step_cutting() {
  local args=(--tets 10583 --step-mm 2 --stroke-mm 120) repeats=5 variant r runs=()
  ((!quick)) || { args=(--tets 2000 --step-mm 4 --stroke-mm 120) repeats=1; }
  local variants=("2 $repeats" "2 $repeats" "2 1" "2 1" "2 1" "1 $repeats" "1 $repeats")
  ((!quick)) || variants=("2 1" "1 1")
  run "$cli" bench-cut "${args[@]}" --threads 2 --repeats "$repeats" --output-dir "$out"
  for variant in "${variants[@]}"; do
    r=$((${#runs[@]} + 1))
    ((listing)) || mkdir -p "$w/run-$r"
    run "$cli" bench-cut "${args[@]}" --threads "${variant% *}" --repeats "${variant#* }" \
      --output-dir "$w/run-$r"
    runs+=("$w/run-$r/cutting-performance.md")
  done
  doing || return 0
  {
    echo "| command | updates that cut: median (ms) | 95th percentile (ms) | max (ms) | every update: median (ms) | 95th percentile (ms) | max (ms) |"
    echo "|---|---:|---:|---:|---:|---:|---:|"
    for r in "${!runs[@]}"; do
      awk -F' *[|] *' -v command="${commands[r + 1]}" '
        /^[|] updates that cut, whole/ { cut = $4 " | " $5 " | " $6 }
        /^[|] every update/ { every = $4 " | " $5 " | " $6 }
        END { printf "| `%s` | %s | %s |\n", command, cut, every }' "${runs[r]}"
    done
  } >"$w/runs.md"
  stamp cutting-performance.md 0 1
  splice cutting.md bench-cut-runs "$w/runs.md"
  stamp cutting.md
}

step_haptics-servo() {
  local args=(--seconds 5 --runs 3 --tets 10583)
  ((!quick)) || args=(--seconds 0.5 --runs 1 --tets 1500)
  run "$cli" bench-servo "${args[@]}" --output-dir "$out"
  doing || return 0
  stamp haptics-servo.md
}

step_rendering-performance() {
  local args=(--tets "5406,10583" --frames 300 --width 1280 --height 800)
  ((!quick)) || args=(--tets 1000 --frames 10 --width 320 --height 200)
  run_x "$cli" render-bench "${args[@]}" --output-dir "$out"
  doing || return 0
  stamp rendering-performance.md
}

# The elastic study at the seed's five sizes, and the effects study at the smallest.
step_accuracy-study() {
  local grid=(--integrators "central-difference,rk4,dopri5,backward-euler,bdf2" --steps-ms "1,0.5,0.25"
    --tolerances "1e-07,1e-09,1e-11" --duration 0.05 --force 0.63 --refinement 64)
  local elastic=(--tets "3841,5406,7312,9371,10583") effects=(--tets 3841)
  if ((quick)); then
    grid=(--integrators "central-difference,backward-euler" --steps-ms "1,0.5" --tolerances 1e-07
      --duration 0.004 --force 0.63 --refinement 4)
    elastic=(--tets "1000,1500") effects=(--tets 1000)
  fi
  ((listing)) || mkdir -p "$out/accuracy-study-effects"
  run_x "$cli" study accuracy "${elastic[@]}" --effects elastic "${grid[@]}" --output-dir "$out"
  run_x "$cli" study accuracy "${effects[@]}" --effects "viscoelastic,viscoplastic,fibres" \
    "${grid[@]}" --output-dir "$out/accuracy-study-effects"
  doing || return 0
  stamp accuracy-study.md 0 1
  stamp accuracy-study-effects/accuracy-study.md 1 2
}

# integrators.md: the seed's recipe and an implicit step as the commands print them, and every
# scheme and setting of the elastic accuracy study at the mesh nearest the seed's 5406
# tetrahedra (from its CSV as it stands: run after accuracy-study).
step_integrators() {
  local size=5406 time=0.1 name
  ((!quick)) || { size=1000 time=0.01; }
  run --stdout "$w/seed-recipe.txt" "$cli" experiment timing --integrator rk4 --dt 0.002 \
    --tets "$size" --time "$time"
  run --stdout "$w/seed-recipe-zhang.txt" "$cli" simulate --mesh "${zhang[@]}" --integrator rk4 \
    --dt 0.002 --time "$time"
  ((quick)) || size=3841
  run --stdout "$w/backward-euler.txt" "$cli" simulate --tets "$size" --integrator backward-euler \
    --dt 0.002 --time "$time"
  doing || return 0
  for name in seed-recipe seed-recipe-zhang backward-euler; do fenced "$w/$name.txt" >"$w/$name.md"; done
  splice integrators.md seed-recipe "$w/seed-recipe.md" 0 1
  splice integrators.md seed-recipe-zhang "$w/seed-recipe-zhang.md" 1 2
  splice integrators.md backward-euler "$w/backward-euler.md" 2 3
  python3 - "$out/accuracy-study.csv" >"$w/summary.md" <<'PYTHON'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["effects"] == "elastic"]
tets = min({int(r["tets"]) for r in rows}, key=lambda t: abs(t - 5406))
print(f"From [accuracy-study.csv](accuracy-study.csv): elastic tissue, {tets} tetrahedra, one thread;"
      " error against the study's reference run (accuracy-study.md says which); cost in wall"
      " seconds per simulated second.")
print()
print("| scheme | requested | mean step (ms) | steps shortened by the stability limit | max node error (mm) | cost (s/s) |")
print("|---|---|---:|---:|---:|---:|")
for r in rows:
    if int(r["tets"]) == tets:
        tolerance = float(r["tolerance_m"])
        setting = f"tolerance {tolerance:g} m" if tolerance > 0 else f"{float(r['step_s']) * 1e3:g} ms"
        print(f"| {r['integrator']} | {setting} | {float(r['mean_step_s']) * 1e3:.3g} | "
              f"{r['stability_limited_steps']} | {float(r['max_node_error_m']) * 1e3:.2g} | "
              f"{float(r['wall_per_simulated_s']):.3g} |")
PYTHON
  splice integrators.md accuracy-summary "$w/summary.md"
  stamp integrators.md
}

step_stability-report() {
  local args=(--shared-data "$shared" --long-run 600 --sweep-samples 24 --sweep-seed 20261121)
  ((!quick)) || args=(--case non-finite-injection --case floating-fragment --case free-liver
    --case parameter-sweep --shared-data "$shared" --long-run 2 --sweep-samples 1
    --sweep-seed 20261121)
  # It exits 1 when a check fails, having written the report that says which.
  run --may-fail "$cli" study stability "${args[@]}" --output-dir "$out" ||
    echo "  a check failed: see $out/stability-report.md" >&2
  doing || return 0
  stamp stability-report.md
}

step_soak() {
  local seconds=1800
  ((!quick)) || seconds=65
  run tests/soak/soak.sh "$seconds" "$build" "$w"
  doing || return 0
  splice soak.md soak-run "$w/report.md" 0 1
  stamp soak.md
}

step_training-centre-load() {
  local seconds=600 workstations=20
  ((!quick)) || { seconds=65 workstations=2; }
  run tests/storage/training_centre_load.sh "$build" "$w" fresh "$out/training-centre-load.md" \
    "$seconds" "$workstations"
  doing || return 0
  stamp training-centre-load.md
}

# The fuzz preset: what its CI step costs in a fresh build folder, a long run of each target from
# its seeds and regressions, and the readers' line coverage over what the long runs kept.
step_fuzzing() {
  local seconds=600 fresh=$w/fresh-build coverage=$w/coverage-build long=$w/long
  local targets=() ccache=(env CCACHE_DISABLE=1) short=() marks=() entry target max_len t0 i
  ((!quick)) || { seconds=5 ccache=() short=(-DLIVERSIM_FUZZ_SHORT_SECONDS=2); }
  while IFS='|' read -r target _ max_len; do targets+=("$target|$max_len"); done < <(
    sed -n '/^set(LIVERSIM_FUZZ_TARGETS/,/)/p' tests/fuzz/CMakeLists.txt |
      grep -o '[a-z_]*|[a-z:_]*|[0-9]*')
  run cmake --preset fuzz
  run cmake --build --preset fuzz --parallel "$jobs"
  # The CI step's cost in a fresh folder, without ccache (docs/fuzzing.md, "CI time").
  ((listing)) || rm -rf "$fresh"
  marks+=(${#commands[@]})
  t0=$SECONDS
  run "${ccache[@]}" cmake --preset fuzz -B "$fresh" "${short[@]}"
  local configure_s=$((SECONDS - t0))
  t0=$SECONDS
  run "${ccache[@]}" cmake --build "$fresh" --target liversim_fuzzers --parallel "$jobs"
  local build_s=$((SECONDS - t0))
  t0=$SECONDS
  run ctest --test-dir "$fresh" -L fuzz-short --parallel "$jobs"
  local short_s=$((SECONDS - t0))
  t0=$SECONDS
  run ctest --test-dir "$build" -L '^fuzz$' --parallel "$jobs"
  local replay_s=$((SECONDS - t0))
  # The long runs, one after another, each from a fresh corpus folder.
  marks+=(${#commands[@]})
  local starts=() ends=() statuses=()
  for entry in "${targets[@]}"; do
    target=${entry%|*} max_len=${entry#*|}
    ((listing)) || {
      rm -rf "$long/corpus/$target" "$long/artifacts/$target"
      mkdir -p "$long/corpus/$target" "$long/artifacts/$target"
    }
    local inputs=("tests/fuzz/corpus/$target") dict=() status=0
    [ ! -d "tests/fuzz/regressions/$target" ] || inputs+=("tests/fuzz/regressions/$target")
    [ ! -f "tests/fuzz/dict/$target.dict" ] || dict=("-dict=tests/fuzz/dict/$target.dict")
    starts+=("$(date -u +%H:%M:%S)")
    run --may-fail --output "$long/$target.log" env TMPDIR=/dev/shm \
      LSAN_OPTIONS=suppressions=tests/fuzz/lsan.supp UBSAN_OPTIONS=print_stacktrace=1 \
      "build/fuzz/tests/fuzz/liversim_fuzz_$target" -max_total_time="$seconds" -rss_limit_mb=2048 \
      -max_len="$max_len" -timeout=10 -print_final_stats=1 "${dict[@]}" \
      -artifact_prefix="$long/artifacts/$target/" "$long/corpus/$target" "${inputs[@]}" ||
      status=$?
    ends+=("$(date -u +%H:%M:%S)")
    statuses+=("$status")
  done
  # Line coverage of the readers over the kept corpus, the seeds and the regressions (clang's
  # source-based coverage, in a build of its own).
  marks+=(${#commands[@]})
  run cmake --preset fuzz -B "$coverage" \
    -DCMAKE_C_FLAGS='-fprofile-instr-generate -fcoverage-mapping' \
    -DCMAKE_CXX_FLAGS='-fprofile-instr-generate -fcoverage-mapping'
  run cmake --build "$coverage" --target liversim_fuzzers --parallel "$jobs"
  ((listing)) || { rm -rf "$w/profiles"; mkdir -p "$w/profiles"; }
  local objects=()
  for entry in "${targets[@]}"; do
    target=${entry%|*}
    local inputs=("$long/corpus/$target" "tests/fuzz/corpus/$target")
    [ ! -d "tests/fuzz/regressions/$target" ] || inputs+=("tests/fuzz/regressions/$target")
    run env TMPDIR=/dev/shm LSAN_OPTIONS=suppressions=tests/fuzz/lsan.supp \
      LLVM_PROFILE_FILE="$w/profiles/$target-%p.profraw" \
      "$coverage/tests/fuzz/liversim_fuzz_$target" -runs=0 "${inputs[@]}"
    objects+=(-object "$coverage/tests/fuzz/liversim_fuzz_$target")
  done
  ((listing)) || find "$w/profiles" -name '*.profraw' >"$w/profiles.txt"
  run llvm-profdata-14 merge -sparse --input-files="$w/profiles.txt" -o "$w/merged.profdata"
  local sources=(core/engine/src/mesh_io.cpp core/scenario/src/scenario.cpp
    core/meshing/src/assimp_reading.cpp core/meshing/src/surface_import.cpp
    core/sessions/src/session_store.cpp core/storage/src/sqlite_session_store.cpp)
  run --stdout "$w/coverage.txt" llvm-cov-14 report "${objects[@]:1}" \
    -instr-profile="$w/merged.profdata" "${sources[@]}"
  marks+=(${#commands[@]})
  doing || return 0
  {
    echo "| step | time |"
    echo "|---|---|"
    echo "| configure | $configure_s s |"
    echo "| build (the core and storage libraries and the six targets, clang, sanitizers) | $build_s s |"
    echo "| six short runs, $jobs at a time ($(sed -n 's/^LIVERSIM_FUZZ_SHORT_SECONDS:STRING=//p' \
      "$fresh/CMakeCache.txt") s each) | $short_s s |"
    echo "| **fuzz preset in all** | **$((configure_s + build_s + short_s)) s** |"
    echo "| the six replay programs' tests in the normal build (\`-L fuzz\`) | $replay_s s |"
  } >"$w/ci-time.md"
  splice fuzzing.md ci-time "$w/ci-time.md" "${marks[0]}" "${marks[1]}"
  {
    echo "| target | run (UTC, $(date -u +'%-d %b')) | executions | exec/s | cov | ft | corpus kept | peak RSS | findings |"
    echo "|---|---|---:|---:|---:|---:|---|---|---|"
    i=0
    local kept_files kept_bytes findings
    for entry in "${targets[@]}"; do
      target=${entry%|*}
      kept_files=$(find "$long/corpus/$target" -type f | wc -l)
      kept_bytes=$(du -sb "$long/corpus/$target" | cut -f1)
      findings=$(find "$long/artifacts/$target" -type f -printf '%f ' | sed 's/ $//')
      [ -n "$findings" ] || findings=none
      [ "${statuses[i]}" = 0 ] || [ "$findings" != none ] ||
        findings="exit code ${statuses[i]} (see $long/$target.log)"
      awk -v t="$target" -v when="${starts[i]}–${ends[i]}" -v files="$kept_files" \
        -v bytes="$kept_bytes" -v findings="$findings" '
        /^stat::number_of_executed_units:/ { runs = $2 }
        /^stat::average_exec_per_sec:/ { rate = $2 }
        /^stat::peak_rss_mb:/ { rss = $2 }
        / cov: / { for (k = 1; k < NF; ++k) { if ($k == "cov:") cov = $(k + 1); if ($k == "ft:") ft = $(k + 1) } }
        END {
          size = bytes >= 1e6 ? sprintf("%.1f MB", bytes / 1e6) : sprintf("%.0f kB", bytes / 1e3)
          printf "| `%s` | %s | %s | %s | %s | %s | %d inputs, %s | %s MB | %s |\n",
                 t, when, runs, rate, cov, ft, files, size, rss, findings }' "$long/$target.log"
      i=$((i + 1))
    done
  } >"$w/long-runs.md"
  # The first target's command stands for all six's (the others differ by name and -max_len).
  # shellcheck disable=SC2016 # the backquotes are Markdown's
  sed -i '1i The same for each target, with its own `-max_len`, dictionary and folders:\n' \
    "$w/long-runs.md"
  splice fuzzing.md long-runs "$w/long-runs.md" "${marks[1]}" $((marks[1] + 1))
  # llvm-cov's report: file, regions, missed, cover, functions, missed, executed, lines, missed,
  # cover, branches, missed, cover.
  awk '$1 ~ /\.cpp$/ { n = split($1, path, "/")
         printf "coverage/%s/lines\t%s\ncoverage/%s/branches\t%s\n", path[n], $10, path[n], $13 }' \
    "$w/coverage.txt" | sed 's/%$//' >"$w/figures.tsv"
  fill fuzzing.md "$w/figures.tsv"
  stamp fuzzing.md
}

# The sanitizers' runs: the whole suite under ASan + UBSan, the threaded parts under TSan (the CI
# step), the bad-input tests under ASan + UBSan in the fuzz build (the CI step).
step_sanitizers() {
  local asan_targets=() asan_filter=() tsan_filter=() inputs_filter=() marks=() i
  local tsan_targets=(liversim_threads_tests liversim_station_tests liversim_storage_tests
    liversim_training_centre_tests liversim_cli_record_tests liversim-cli
    liversim_session_writer_child)
  if ((quick)); then
    asan_targets=(--target liversim_fuzz_trace_chunks_replay) asan_filter=(-R '^fuzz[.]trace_chunks')
    tsan_targets=(liversim_threads_tests) tsan_filter=(-R '^SpscRing')
    inputs_filter=(-R '^FrameChunk')
  fi
  run cmake --preset asan
  run cmake --build --preset asan --parallel "$jobs" "${asan_targets[@]}"
  marks+=(${#commands[@]})
  run --may-fail --stdout "$w/asan.txt" "${xvfb[@]}" ctest --preset asan --parallel "$jobs" \
    "${asan_filter[@]}" || true
  run cmake --preset tsan
  run cmake --build --preset tsan --parallel "$jobs" --target "${tsan_targets[@]}"
  marks+=(${#commands[@]})
  run --may-fail --stdout "$w/tsan.txt" ctest --preset tsan-threads --parallel "$jobs" \
    "${tsan_filter[@]}" || true
  run cmake --preset fuzz
  run cmake --build --preset fuzz --parallel "$jobs"
  marks+=(${#commands[@]})
  run --may-fail --stdout "$w/inputs.txt" ctest --preset asan-inputs --parallel "$jobs" \
    "${inputs_filter[@]}" || true
  doing || return 0
  local names=("ASan+UBSan, whole suite" "TSan, the threaded parts (the CI step)"
    "ASan+UBSan, \`clang\`, the bad-input tests (the CI step)") files=(asan tsan inputs)
  {
    echo "| run | command | tests | result | wall time |"
    echo "|---|---|---:|---|---:|"
    for i in 0 1 2; do
      awk -v run="${names[i]}" -v command="${commands[marks[i]]}" '
        /tests passed, .* tests failed out of/ { failed = $4; total = $NF }
        /^Total Test time [(]real[)]/ { time = $(NF - 1) }
        /The following tests FAILED:/ { listing = 1; next }
        listing && /^[[:space:]]+[0-9]+ - / { sub(/^[[:space:]]+[0-9]+ - /, ""); names = names (names ? "; " : "") $0; next }
        listing && !/^[[:space:]]/ { listing = 0 }
        END {
          result = (total - failed) " passed"
          if (failed > 0) result = result ", failed: " names
          printf "| %s | `%s` | %s | %s | %s s |\n", run, command, total, result, time }' \
        "$w/${files[i]}.txt"
    done
  } >"$w/runs.md"
  splice sanitizers.md latest-runs "$w/runs.md"
  stamp sanitizers.md
}

step_architecture() {
  run packaging/layers-graph.sh "$build" "$out"
  doing || return 0
  stamp architecture.md
}

# .ci/run on a clean clone of HEAD beside this checkout (the tests read ../shared from there), as
# CI runs it: once with the compiler cache as this machine has it, once without (CCACHE_DISABLE:
# what a new machine's builds cost). Its step lines ("liversim: step NAME took S s") and test
# counts make the table. Each run is on a fresh clone (its builds from nothing). --quick clones and
# runs the set-up step only.
step_ci() {
  local clone mode cache
  clone=$(dirname "$root")/liversim-ci-measure
  for mode in cached uncached; do
    # ccache takes no "0": the cached run leaves the variable unset.
    if [ "$mode" = uncached ]; then cache=(CCACHE_DISABLE=1); else cache=(-u CCACHE_DISABLE); fi
    ((listing)) || rm -rf "$clone"
    run git clone --quiet "$root" "$clone"
    if ((quick)); then
      run --output "$w/$mode.log" env "${cache[@]}" "$clone/packaging/setup-debian.sh"
    else
      run --output "$w/$mode.log" env "${cache[@]}" CI=true \
        bash -c 'start=$SECONDS; "$1/.ci/run"; status=$?; echo "liversim: step whole run took $((SECONDS - start)) s"; exit $status' \
        ci-run "$clone"
    fi
  done
  doing || return 0
  rm -rf "$clone"
  python3 - "$w/cached.log" "$w/uncached.log" >"$w/runs.md" <<'PYTHON'
import re, sys
logs = [open(path, encoding="utf-8").read() for path in sys.argv[1:3]]
def steps(log):
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"liversim: step (.+?) took (\d+) s", log)}
def tests(log):
    return re.findall(r"(\d+)% tests passed, (\d+) tests failed out of (\d+)", log)
cached, uncached = steps(logs[0]), steps(logs[1])
print("| step | with this machine's compiler cache (s) | without a compiler cache (s) |")
print("|---|---|---|")
for name in cached:
    fmt = lambda d: f"{d[name]} ({d[name] / 60:.1f} min)" if name in d else "-"
    print(f"| {name} | {fmt(cached)} | {fmt(uncached)} |")
print()
counts = tests(logs[0])
suites = ["release suite", "fuzz short runs", "asan-inputs", "tsan-threads"]
print("Tests run (with the cache): " + "; ".join(
    f"{suites[i] if i < len(suites) else 'suite ' + str(i)}: {int(total) - int(failed)}/{total}"
    for i, (_, failed, total) in enumerate(counts)) + ".")
budget = re.search(r"test budget: (\d+) tests, (\d+) s of test time; the slowest:\n((?:  .*\n)+)", logs[0])
if budget:
    print()
    print(f"The release suite's {budget.group(1)} tests took {budget.group(2)} s of test time; the slowest "
          "(packaging/test-budget.py):")
    print()
    print("```")
    print(budget.group(3).rstrip())
    print("```")
PYTHON
  splice ci.md ci-runs "$w/runs.md" 0 "${#commands[@]}"
  stamp ci.md
}

# ---- The run ------------------------------------------------------------------------------------
minutes() { # STEP
  local full fast
  read -r full fast <<<"${minutes_of[$1]}"
  if ((quick)); then echo "$fast"; else echo "$full"; fi
}

if ((listing)); then
  total=0
  echo "build: packaging/setup-debian.sh --measuring; cmake --preset release;" \
    "cmake --build --preset release (not counted below)"
  for step in "${selected[@]}"; do
    page_list=""
    for page in ${pages[$step]}; do page_list+="${page_list:+, }docs/$page"; done
    note=""
    ((quick)) || note=${step_notes[$step]:-}
    echo "$step: $page_list (about $(minutes "$step") min${note:+; $note})"
    commands=()
    w=$work/$step
    "step_$step"
    total=$((total + $(minutes "$step")))
  done
  echo "in all: about $total min ($((total / 60)) h $((total % 60)) min)"
  exit 0
fi

started=$SECONDS
mkdir -p "$work/logs"
echo "regenerate-docs: commit $commit; $cpu ($cores cores, $ram_gib GiB); pages into $out"
packaging/setup-debian.sh --measuring
# ccache (setup-debian.sh installs it) keys objects on paths relative to the checkout.
export CCACHE_BASEDIR=$root
echo "regenerate-docs: building the release preset (log: $work/logs/build.log)"
{
  cmake --preset release && cmake --build --preset release --parallel "$jobs"
} >"$work/logs/build.log" 2>&1 || {
  tail -n 30 "$work/logs/build.log" >&2
  exit 1
}
if ((quick)); then
  # A scratch copy of the pages (with their images and CSVs) to rewrite.
  rm -rf "$out"
  mkdir -p "$out"
  cp -r docs/. "$out/"
fi

failed=()
for step in "${selected[@]}"; do
  w=$work/$step
  mkdir -p "$w"
  log=$work/logs/$step.log
  : >"$log"
  commands=()
  echo "regenerate-docs: $step (about $(minutes "$step") min): ${pages[$step]}"
  t0=$SECONDS
  # In a subshell with errexit on, so that a failing command ends its step only.
  set +e
  (
    set -e
    "step_$step"
  )
  status=$?
  set -e
  if ((status == 0)); then
    echo "  done in $((SECONDS - t0)) s"
  else
    echo "regenerate-docs: $step FAILED after $((SECONDS - t0)) s (log: $log)" >&2
    failed+=("$step")
  fi
done
echo "regenerate-docs: ${#selected[@]} steps in $((SECONDS - started)) s; pages in $out"
if ((${#failed[@]})); then
  echo "regenerate-docs: failed: ${failed[*]}" >&2
  exit 1
fi
