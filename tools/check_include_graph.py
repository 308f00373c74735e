#!/usr/bin/env python3
"""The include rule: the include graph has no arrow back into src/.

Rules, checked on every quoted #include of the tree at ROOT:
  * sensors/ and display/ include nothing from src/ except src/common (the one base every
    stage may use);
  * src/common includes nothing from another stage (a base depends on no stage);
  * src/contact (the contact stage) includes from src/ only common, fem, model, scene and
    itself: not the bridge, the app or LCM, which use it;
  * src/render (display rendering) likewise: common, fem, model, scene and itself;
  * src/lcm puts structs on the wire: it may read the contact stage's plain structs, not
    the bridge or the app;
  * src/bridge may include every stage but the app and the benchmark;
  * no runtime stage of src/ includes src/fidelity or src/app: the offline benchmark is for
    the app, the tools and the tests, and stays off the runtime libraries.
An include "X/..." is a src/ include when src/X is a folder (the build's include roots are
src/ and the project root, so "fem/tet_mesh.h" is src/fem/tet_mesh.h).

Usage: check_include_graph.py [ROOT]; exit 0 when clean, 1 listing every offending line.
"""
import os
import re
import sys

import tree_check

INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')
SOURCE_SUFFIXES = (".h", ".hpp", ".cpp", ".cc")


def stage_of(include, src_stages):
    """The src/ stage an include points into, or None when it is not a src/ include."""
    parts = include.split("/")
    if parts[0] == "src" and len(parts) > 1:
        return parts[1]
    return parts[0] if parts[0] in src_stages and len(parts) > 1 else None


def violations(root):
    src = os.path.join(root, "src")
    src_stages = {d for d in os.listdir(src) if os.path.isdir(os.path.join(src, d))}
    # folder checked -> stages it may include from src/
    allowed = {
        "sensors": {"common"},
        "display": {"common"},
        os.path.join("src", "common"): {"common"},
        os.path.join("src", "contact"): {"common", "fem", "model", "scene", "contact"},
        os.path.join("src", "render"): {"common", "fem", "model", "scene", "render"},
        os.path.join("src", "lcm"): {"common", "contact", "lcm"},
        os.path.join("src", "bridge"): {"common", "fem", "model", "scene", "contact", "render", "lcm", "bridge"},
    }
    for stage in sorted(src_stages - {"common", "fidelity", "app"}):
        allowed.setdefault(os.path.join("src", stage), src_stages - {"fidelity", "app"})
    found = []
    for folder, may in allowed.items():
        for dirpath, _, files in os.walk(os.path.join(root, folder)):
            for name in sorted(files):
                if not name.endswith(SOURCE_SUFFIXES):
                    continue
                path = os.path.join(dirpath, name)
                with open(path, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        stage = stage_of(m.group(1), src_stages)
                        if stage is not None and stage not in may:
                            found.append("%s:%d: %s includes src/%s (allowed from src/: %s)" % (
                                os.path.relpath(path, root), number, folder, m.group(1).removeprefix("src/"),
                                ", ".join(sorted(may))))
    return found


def main():
    return tree_check.main(violations,
                           "include graph: %d arrow(s) against the stage order (see tools/check_include_graph.py)",
                           "include graph: sensors/, display/ and src/common include nothing from src/ but src/common; "
                           "contact, render, lcm and bridge keep their stage order; no runtime stage includes src/fidelity")


if __name__ == "__main__":
    sys.exit(main())
