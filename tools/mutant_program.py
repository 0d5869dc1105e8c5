#!/usr/bin/env python3
"""Writes the kernel program as the build embeds it, with one mutation (tools/mutate.sh).

    mutant_program.py ROOT OUT [FILE TEXT REPLACEMENT]

The program is the files of CMakeLists.txt's PORTALSIM_KERNELS list, in its order, joined
by a newline (cmake/embed.cmake). With a mutation, TEXT must occur exactly once in FILE.
"""
import pathlib
import re
import sys


def main() -> int:
    root, out, *mutation = sys.argv[1:]
    cmake = (pathlib.Path(root) / "CMakeLists.txt").read_text(encoding="utf-8")
    files = re.search(r"set\(PORTALSIM_KERNELS\s+([^)]*)\)", cmake).group(1).split()
    texts = {f: (pathlib.Path(root) / f).read_text(encoding="utf-8") for f in files}
    if mutation:
        file, old, new = mutation
        n = texts[file].count(old) if file in texts else -1
        if n != 1:
            sys.exit(f"{file}: the mutation's text occurs {n} times (must be once): {old}")
        texts[file] = texts[file].replace(old, new)
    pathlib.Path(out).write_text("\n".join(texts[f] for f in files), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
