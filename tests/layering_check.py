#!/usr/bin/env python3
"""Fails when a header or source under host/ includes one from a layer above its own.

The layers, lowest first: a folder may include its own layer and any layer below it.
The kernels' shared header (kernels/shared.h, included as "shared.h") sits below all.
"""
import pathlib
import re
import sys
import tempfile

LAYERS = ["base", "io", "scene", "assets", "plan", "backend", "sink", "schedule", "serve", "cli"]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def check(host: pathlib.Path) -> list[str]:
    rank = {name: i for i, name in enumerate(LAYERS)}
    problems = []
    folders = {p.name for p in host.iterdir() if p.is_dir()}
    for unknown in sorted(folders - set(rank)):
        problems.append(f"host/{unknown}/: folder has no place in the layer list of {__file__}")
    for path in sorted(host.rglob("*")):
        if path.suffix not in (".h", ".cpp") or not path.is_file():
            continue
        layer = path.relative_to(host).parts[0]
        if layer not in rank:
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or "/" not in m.group(1):
                continue
            target = m.group(1).split("/")[0]
            if target in rank and rank[target] > rank[layer]:
                problems.append(f"{path.relative_to(host.parent)}:{n}: {layer} includes \"{m.group(1)}\" "
                                f"from {target}, a layer above it")
    return problems


def self_test() -> None:
    """The check must catch an upward include, so that it cannot pass by accident."""
    with tempfile.TemporaryDirectory() as tmp:
        host = pathlib.Path(tmp) / "host"
        for layer in LAYERS:
            (host / layer).mkdir(parents=True)
        (host / "scene" / "a.h").write_text('#include "io/ok.h"\n#include "cli/common.h"\n')
        found = check(host)
        assert len(found) == 1 and "scene/a.h:2" in found[0], found


def main() -> int:
    self_test()
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    problems = check(root / "host")
    for p in problems:
        print(p)
    print(f"layering: {len(problems)} problem(s)" if problems else "layering: every include points down or across")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
