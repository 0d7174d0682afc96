#!/usr/bin/env bash
# Draws docs/images/layers.svg, the project's libraries and how they link, from the CMake targets
# of a configured build (cmake --graphviz, then Graphviz's dot): the picture in
# docs/architecture.md. Usage: packaging/layers-graph.sh [BUILD_DIR [DOCS_DIR]] (default
# build/release and docs).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${1:-"$root/build/release"}
docs=${2:-"$root/docs"}
command -v dot >/dev/null || { echo "layers-graph: Graphviz's dot is missing (apt-get install graphviz)" >&2; exit 1; }
[ -f "$build/CMakeCache.txt" ] || { echo "layers-graph: $build is not a configured build" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# cmake reads its graph options from the build folder.
cp "$root/packaging/CMakeGraphVizOptions.cmake" "$build/"
cmake --graphviz="$work/targets.dot" "$build" >/dev/null
rm "$build/CMakeGraphVizOptions.cmake"
# Without the legend; the lowest layer at the bottom, arrows pointing at what a library links.
python3 - "$work/targets.dot" "$work/layers.dot" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
text = re.sub(r"subgraph clusterLegend \{.*?\n\}\n", "", text, flags=re.S)
text = re.sub(r"\\n\(liversim::[a-z]+\)", "", text)
text = text.replace("{", '{\nnode [ shape = box, style = rounded, fontname = "DejaVu Sans" ];\n'
                    'edge [ color = "#555555" ];', 1)
open(sys.argv[2], "w").write(text)
PY
mkdir -p "$docs/images"
dot -Tsvg "$work/layers.dot" -o "$docs/images/layers.svg"
echo "layers-graph: wrote $docs/images/layers.svg"
