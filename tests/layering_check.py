#!/usr/bin/env python3
"""Fails when an include breaks the layering of host/ or the reference's independence.

1. The layers, lowest first: a folder may include its own layer and any layer below it.
   The kernels' contract header (kernels/contract.h, included as "contract.h") sits below all.
2. The CPU reference (host/backend/reference/) may share with the kernels only the contract
   header: no file it reaches through any chain of includes may be another header of
   kernels/ or a file of host/backend/opencl/, which hold computations.
3. The contract header holds constants and layouts only: no function-like macro, no function.
"""
import pathlib
import re
import sys
import tempfile

LAYERS = ["base", "io", "scene", "assets", "plan", "backend", "sink", "calibrate", "schedule", "evaluate", "serve", "cli"]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
CONTRACT = "kernels/contract.h"
REFERENCE = "host/backend/reference"
COMPUTING = ("kernels/", "host/backend/opencl/")  # where a reached file other than CONTRACT is refused
FUNCTION_MACRO = re.compile(r"^\s*#\s*define\s+\w+\(")
FUNCTION = re.compile(r"\b\w+\s*\([^()]*\)\s*(\{|;|const\b)")


def includes(path: pathlib.Path):
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = INCLUDE.match(line)
        if m:
            yield n, m.group(1)


def layer_problems(host: pathlib.Path) -> list[str]:
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
        for n, name in includes(path):
            if "/" not in name:
                continue
            target = name.split("/")[0]
            if target in rank and rank[target] > rank[layer]:
                problems.append(f"{path.relative_to(host.parent)}:{n}: {layer} includes \"{name}\" "
                                f"from {target}, a layer above it")
    return problems


def resolve(root: pathlib.Path, including: pathlib.Path, name: str):
    """The file an #include "name" reaches: beside the includer, then the include
    directories host/ and kernels/ (CMakeLists.txt's order)."""
    for base in (including.parent, root / "host", root / "kernels"):
        p = base / name
        if p.is_file():
            return p.resolve()
    return None  # a system or generated header: not ours


def reference_problems(root: pathlib.Path) -> list[str]:
    problems = []
    ref = root / REFERENCE
    if not ref.is_dir():
        return [f"{REFERENCE}/: missing"]
    for start in sorted(p for p in ref.rglob("*") if p.suffix in (".h", ".cpp") and p.is_file()):
        chain = {start.resolve(): [start.relative_to(root).as_posix()]}
        todo = [start.resolve()]
        while todo:
            path = todo.pop()
            for _, name in includes(path):
                target = resolve(root, path, name)
                if target is None or target in chain:
                    continue
                chain[target] = chain[path] + [target.relative_to(root.resolve()).as_posix()]
                rel = chain[target][-1]
                if rel != CONTRACT and rel.startswith(COMPUTING):
                    problems.append(f"{' -> '.join(chain[target])}: the reference reaches {rel}, which holds "
                                    f"computations; it may share only {CONTRACT} with the kernels")
                    continue
                todo.append(target)
    return sorted(set(problems))


def contract_problems(root: pathlib.Path) -> list[str]:
    path = root / CONTRACT
    if not path.is_file():
        return [f"{CONTRACT}: missing"]
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), path.read_text(encoding="utf-8"), flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    problems = []
    for n, line in enumerate(text.splitlines(), 1):
        if FUNCTION_MACRO.match(line):
            problems.append(f"{CONTRACT}:{n}: a function-like macro; computations live on each side")
        elif not line.lstrip().startswith("#") and FUNCTION.search(line):
            problems.append(f"{CONTRACT}:{n}: a function; computations live on each side")
    return problems


def check(root: pathlib.Path) -> list[str]:
    return layer_problems(root / "host") + reference_problems(root) + contract_problems(root)


def self_test() -> None:
    """Each rule must catch its breach, so that the check cannot pass by accident."""
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        host = root / "host"
        for layer in LAYERS:
            (host / layer).mkdir(parents=True)
        (host / "backend" / "reference").mkdir()
        (host / "backend" / "opencl").mkdir()
        (root / "kernels").mkdir()
        (root / CONTRACT).write_text("#define PS_A 1\ntypedef struct {\n  int n; /* f(x) */\n} PsLayout;\n")
        (root / "kernels" / "shared.h").write_text('#include "contract.h"\n#define PS_F(x) ((x) + 1)\n')
        (host / "scene" / "a.h").write_text('#include "io/ok.h"\n#include "cli/common.h"\n#include "contract.h"\n')
        (host / "backend" / "reference" / "ok.cpp").write_text('#include "scene/a.h"\n')
        found = check(root)
        assert len(found) == 1 and "scene/a.h:2" in found[0], found
        # Two steps down a chain, a kernel-side header; one step, an OpenCL host file.
        (host / "scene" / "b.h").write_text('#include "shared.h"\n')
        (host / "backend" / "reference" / "far.cpp").write_text('#include "scene/b.h"\n')
        (host / "backend" / "opencl" / "x.h").write_text("\n")
        (host / "backend" / "reference" / "near.h").write_text('#include "backend/opencl/x.h"\n')
        found = reference_problems(root)
        assert len(found) == 2, found
        assert "far.cpp -> host/scene/b.h -> kernels/shared.h" in found[0], found
        assert "near.h -> host/backend/opencl/x.h" in found[1], found
        assert not contract_problems(root)
        (root / CONTRACT).write_text("#define PS_A 1\n#define PS_B(x) (x)\ninline int f(int x) { return x; }\n")
        found = contract_problems(root)
        assert len(found) == 2 and ":2:" in found[0] and ":3:" in found[1], found


def main() -> int:
    self_test()
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    problems = check(root)
    for p in problems:
        print(p)
    print(f"layering: {len(problems)} problem(s)" if problems else
          "layering: every include points down or across, and the reference shares only the contract header")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
