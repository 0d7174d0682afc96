#!/usr/bin/env bash
# The soak of docs/soak.md: a long recorded session with scripted device input at 1 kHz, headless
# (`liversim-cli record`), the forceps grasping and pulling the liver every 6 s. Prints the
# recorder's progress (frames committed, VmRSS, VmHWM), then checks what the issue asks of it and
# exits 1 naming the first check that fails: memory flat, the session complete with every frame
# stored, the database intact. Its figures, as docs/soak.md shows them, go to report.md in the
# output dir (packaging/regenerate-docs.sh puts them in the page).
#   tests/soak/soak.sh [seconds=1800] [build dir=build/release] [output dir=build/soak]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
seconds=${1:-1800}
build=${2:-$root/build/release}
out=${3:-$root/build/soak}
cli="$build/app/liversim-cli"
mkdir -p "$out"
rm -f "$out"/sessions.sqlite*
trajectory="$out/trajectory.txt"
# A cycle of 6 s in device mm: in front of the liver, in 10 mm, close, pull up and aside, back,
# open, out. The device holds the last point after the end.
awk -v seconds="$seconds" 'BEGIN {
  print "# time_s x_mm y_mm z_mm buttons"
  for (t = 0; t + 6 <= seconds; t += 6) {
    printf "%d 0 0 0 0\n%d 0 0 -10 0\n%.1f 0 0 -10 1\n%d 5 8 -4 1\n%.1f 0 0 -10 1\n%d 0 0 -10 0\n",
           t, t + 1, t + 1.5, t + 3, t + 4.5, t + 5
  }
  printf "%d 0 0 0 0\n", t
}' > "$trajectory"
"$cli" record --tool forceps --trajectory "$trajectory" --database "$out/sessions.sqlite" \
  --trainee soak --duration "$seconds" --progress 60 | tee "$out/progress.txt"
"$cli" sessions list --database "$out/sessions.sqlite" | tee "$out/sessions.csv"
integrity=$(sqlite3 "$out/sessions.sqlite" 'PRAGMA integrity_check')
echo "integrity: $integrity"

# The figures of docs/soak.md: the memory reports (the first, one every 5 minutes, the last), the
# session's row, its events and metrics, the database's size by table (SQLite's dbstat).
IFS=, read -r _ _ _ _ _ _ _ status frames rate_hz p99_ms missed dropped < <(tail -n 1 "$out/sessions.csv")
db_bytes=$(stat -c %s "$out/sessions.sqlite")
{
  echo "| elapsed (s) | frames committed | VmRSS (MiB) | VmHWM, peak RSS (MiB) |"
  echo "|---:|---:|---:|---:|"
  awk '/^elapsed/ { n++; t = $2 + 0; line[n] = sprintf("| %d | %d | %s | %s |", t + 0.5, $4, $8, $11);
         keep[n] = (n == 1 || int(t + 0.5) % 300 == 0) }
       END { for (i = 1; i <= n; ++i) if (keep[i] || i == n) print line[i] }' "$out/progress.txt"
  echo
  awk '/^elapsed/ { n++; rss[n] = $8; hwm[n] = $11 }
       END { lo = hi = rss[1]; hlo = hhi = hwm[1]
             for (i = 1; i <= n; ++i) { if (rss[i] < lo) lo = rss[i]; if (rss[i] > hi) hi = rss[i]
                                        if (hwm[i] < hlo) hlo = hwm[i]; if (hwm[i] > hhi) hhi = hwm[i] }
             printf "The %d reports (one a minute; the rest are in `progress.txt` of the output directory): VmRSS %s to %s MiB, VmHWM %s to %s MiB.\n", n, lo, hi, hlo, hhi }' "$out/progress.txt"
  echo
  echo "The session as \`liversim-cli sessions list\` gives it:"
  echo
  echo "| status | frames | servo rate | servo period, 99th percentile | missed deadlines | dropped frames |"
  echo "|---|---:|---:|---:|---:|---:|"
  echo "| $status | $frames | $rate_hz Hz | $p99_ms ms | $missed | $dropped |"
  echo
  echo "- Events: $(sqlite3 "$out/sessions.sqlite" "SELECT group_concat(n || ' ' || kind, ', ') FROM
    (SELECT kind, count(*) AS n FROM events GROUP BY kind ORDER BY n DESC, kind)")."
  echo "- Metrics stored: $(sqlite3 "$out/sessions.sqlite" "SELECT group_concat(name || ' ' ||
    printf('%.6g', value), ', ') FROM (SELECT name, value FROM metrics ORDER BY name)")."
  echo "- \`PRAGMA integrity_check\`: \`$integrity\`."
  awk -v m="$missed" -v f="$frames" 'BEGIN { printf "- Missed deadlines: %d of %d servo ticks (%.3f %%) came later than 1.5 periods.\n", m, f, f ? 100 * m / f : 0 }'
  sqlite3 "$out/sessions.sqlite" "SELECT name, sum(pgsize) FROM dbstat GROUP BY name" |
    awk -F'|' -v db="$db_bytes" -v f="$frames" '{ size[$1] = $2 }
      END { printf "- The database: %.0f MB; force trace (frame_chunks) %.0f MiB, %.0f bytes per frame; the simulation'"'"'s input log (input_chunks) %.0f MiB.\n",
            db / 1e6, size["frame_chunks"] / 1048576, f ? size["frame_chunks"] / f : 0, size["input_chunks"] / 1048576 }'
} > "$out/report.md"

fail() {
  echo "soak: FAILED: $*" >&2
  exit 1
}
# Peak RSS after the first minute (everything allocated at start is in by then) against the end.
# 2 MiB over a 30-minute session is about one byte per servo frame: a leak of anything per frame,
# per grasp or per stored chunk would pass it.
read -r hwm_start hwm_end < <(awk '/VmHWM/ { for (i = 1; i < NF; ++i) if ($i == "VmHWM") v = $(i + 1);
  if (first == "") first = v; last = v } END { print first, last }' "$out/progress.txt")
[ -n "$hwm_start" ] || fail "no memory report in $out/progress.txt (session shorter than 60 s?)"
awk -v a="$hwm_start" -v b="$hwm_end" 'BEGIN { exit !(b - a <= 2.0) }' ||
  fail "peak RSS grew from $hwm_start MiB to $hwm_end MiB"
# The session's row (read above): complete, no frame dropped, the servo within 1 % of 1 kHz for
# the whole time.
[ "$status" = complete ] || fail "session status is '$status', not complete"
[ "$dropped" = 0 ] || fail "$dropped frames dropped"
awk -v f="$frames" -v s="$seconds" 'BEGIN { exit !(f >= 0.99 * 1000 * s) }' ||
  fail "$frames frames stored for $seconds s at 1 kHz"
[ "$integrity" = ok ] || fail "database integrity check: $integrity"
echo "soak: passed: peak RSS $hwm_start MiB after 60 s, $hwm_end MiB at the end; $frames frames, servo $rate_hz Hz, none dropped; database intact"
