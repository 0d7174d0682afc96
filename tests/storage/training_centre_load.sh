#!/usr/bin/env bash
# The training centre's load figures in docs/training-centre-load.md: records one 10-minute
# session at 1 kHz headless (tests/soak/soak.sh: scripted forceps, the workstation's recorder),
# then has 20 workstations upload a copy of it each to one throwaway PostgreSQL server at once.
#   tests/storage/training_centre_load.sh [build dir=build/release] [work dir=build/load]
#       [reuse|fresh=fresh] [page=docs/training-centre-load.md] [seconds=600] [workstations=20]
# With "reuse", the session recorded there by an earlier run (the same soak.sh SECONDS) is used
# again. The page is written whole (packaging/regenerate-docs.sh gives it its own first line).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$root/build/release}
work=${2:-$root/build/load}
reuse=${3:-fresh}
page=${4:-$root/docs/training-centre-load.md}
seconds=${5:-600}
workstations=${6:-20}
if [ "$reuse" != reuse ] || [ ! -f "$work/sessions.sqlite" ]; then
  "$root/tests/soak/soak.sh" "$seconds" "$build" "$work"
fi
{
  echo "# Training centre: $workstations workstations uploading at once"
  echo
  echo "Written by \`tests/storage/training_centre_load.sh\` on $(date -u +%Y-%m-%d)" \
    "($(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -n 1), $(nproc) cores)."
  echo
  echo "PostgreSQL $(find /usr/lib/postgresql -mindepth 1 -maxdepth 1 -printf '%f\n' | sort -n |
    tail -n 1) on loopback, fsync on. Each workstation uploads a copy of the"
  echo "same recorded session of $seconds s (new UUID) from its own SQLite file, in its own thread and"
  echo "connection, all starting together. Chunk bytes are the frame and input chunks as stored"
  echo "(the session's other rows are small); throughput is all of them over the wall time."
  echo
  "$build/tests/storage/liversim_training_centre_load" --template "$work/sessions.sqlite" \
    --workstations "$workstations" --work "$work/workstations"
} > "$work/report.md"
cp "$work/report.md" "$page"
cat "$page"
