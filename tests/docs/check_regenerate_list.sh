#!/usr/bin/env bash
# Checks packaging/regenerate-docs.sh --list against docs/ (tests/docs/CMakeLists.txt):
# - every page it lists exists;
# - every page of docs/ with a line "Written by `…" or "Measured at commit …", a block
#   "<!-- begin NAME -->" or a figure "<!-- fig:KEY -->" is listed (a new figure page cannot be
#   forgotten);
# - every block the script splices into a page has its begin and end lines there.
#   tests/docs/check_regenerate_list.sh [source dir]
set -euo pipefail
root=${1:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}
cd "$root"
listing=$(packaging/regenerate-docs.sh --list)
mapfile -t listed < <(grep -v '^ ' <<<"$listing" | grep -o 'docs/[^ ,()]*\.md' | sort -u)
((${#listed[@]})) || { echo "regenerate-docs.sh --list lists no page" >&2; exit 1; }
problems=0
for page in "${listed[@]}"; do
  [ -f "$page" ] || { echo "listed but missing: $page" >&2; problems=1; }
done
while IFS= read -r page; do
  if [[ " ${listed[*]} " != *" $page "* ]]; then
    echo "$page has measured figures (a 'Written by'/'Measured at' line or a generated block or" \
      "figure) but packaging/regenerate-docs.sh does not list it" >&2
    problems=1
  fi
done < <(grep -rlE '^(Written by `|Measured at commit )|<!-- (begin [a-z0-9-]+|fig:[^ ]+) -->' \
  --include='*.md' docs | sort)
# The blocks the script splices: `splice PAGE NAME ...`.
while read -r page name; do
  for line in "<!-- begin $name -->" "<!-- end $name -->"; do
    grep -qxF "$line" "docs/$page" ||
      { echo "docs/$page has no line '$line' (packaging/regenerate-docs.sh splices it)" >&2; problems=1; }
  done
done < <(grep -oE '^\s*splice [^ ]+\.md [a-z0-9-]+' packaging/regenerate-docs.sh | awk '{ print $2, $3 }')
((problems == 0)) && echo "regenerate-docs.sh lists ${#listed[@]} pages; every figure page of docs/ is among them"
exit "$problems"
