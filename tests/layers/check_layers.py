#!/usr/bin/env python3
"""Every include of a core layer's header from a core source stays within what that layer links.

Reads the layers' links from core/<layer>/CMakeLists.txt (liversim_layer(NAME PUBLIC ...)),
closes them transitively, and checks every `#include "liversim/<layer>/..."` under core/<layer>/
against them. Prints each include that runs back up (file:line: what it includes, what the layer
may see) and exits 1 when there is one. CMake refuses such an include too (the headers of a layer
not linked are not on the include path: tests/layers/probe_*.cpp); this names all of them at once.

Usage: check_layers.py SOURCE_DIR
"""
import pathlib
import re
import sys


def main() -> int:
    root = pathlib.Path(sys.argv[1])
    core = root / "core"
    links = {}
    for cmake in sorted(core.glob("*/CMakeLists.txt")):
        text = cmake.read_text()
        m = re.search(r"liversim_layer\((\w+)(.*?)\)", text, re.S)
        if not m:
            continue
        public = re.search(r"PUBLIC(.*?)(PRIVATE|$)", m.group(2), re.S)
        deps = re.findall(r"liversim::(\w+)", public.group(1)) if public else []
        links[m.group(1)] = deps

    def seen(layer, acc=None):
        acc = set() if acc is None else acc
        for dep in links.get(layer, []):
            if dep not in acc:
                acc.add(dep)
                seen(dep, acc)
        return acc

    problems = 0
    include = re.compile(r'#include "liversim/(\w+)/')
    for layer in links:
        allowed = seen(layer) | {layer}
        for path in sorted((core / layer).rglob("*")):
            if path.suffix not in (".h", ".cpp"):
                continue
            for number, line in enumerate(path.read_text().splitlines(), 1):
                m = include.search(line)
                if m and m.group(1) not in allowed:
                    problems += 1
                    print(f"{path.relative_to(root)}:{number}: includes {m.group(1)}, but {layer} "
                          f"links only {', '.join(sorted(allowed - {layer})) or 'nothing'}")
    if not links:
        print("no layer found under core/", file=sys.stderr)
        return 2
    print(f"{len(links)} layers: " + "; ".join(
        f"{l} -> {', '.join(links[l]) or '-'}" for l in links))
    if problems:
        print(f"{problems} include(s) run back up")
        return 1
    print("no include runs back up")
    return 0


if __name__ == "__main__":
    sys.exit(main())
