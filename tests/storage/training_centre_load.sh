#!/usr/bin/env bash
# The training centre's load figures in docs/training-centre-load.md: records one 10-minute
# session at 1 kHz headless (tests/soak/soak.sh: scripted forceps, the workstation's recorder),
# then has 20 workstations upload a copy of it each to one throwaway PostgreSQL server at once.
#   tests/storage/training_centre_load.sh [build dir=build/release] [work dir=build/load] [reuse]
# With "reuse", the session recorded there by an earlier run (the same soak.sh 600) is used again.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$root/build/release}
work=${2:-$root/build/load}
if [ "${3:-}" != reuse ] || [ ! -f "$work/sessions.sqlite" ]; then
  "$root/tests/soak/soak.sh" 600 "$build" "$work"
fi
{
  echo "# Training centre: 20 workstations uploading at once"
  echo
  echo "Written by \`tests/storage/training_centre_load.sh\` on $(date -u +%Y-%m-%d), $(nproc) cores,"
  echo "$(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -n 1); PostgreSQL"
  echo "$(ls /usr/lib/postgresql | sort -n | tail -n 1) on loopback, fsync on. Each workstation uploads a copy of the"
  echo "same recorded 10-minute session (new UUID) from its own SQLite file, in its own thread and"
  echo "connection, all starting together. Chunk bytes are the frame and input chunks as stored"
  echo "(the session's other rows are small); throughput is all of them over the wall time."
  echo
  "$build/tests/storage/liversim_training_centre_load" --template "$work/sessions.sqlite" \
    --workstations 20 --work "$work/workstations"
} > "$work/report.md"
cp "$work/report.md" "$root/docs/training-centre-load.md"
cat "$root/docs/training-centre-load.md"
