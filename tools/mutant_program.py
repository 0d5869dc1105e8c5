#!/usr/bin/env python3
"""Writes the kernel program as the build embeds it, with one mutation (tools/mutate.sh).

    mutant_program.py ROOT OUT [FILE TEXT REPLACEMENT]
    mutant_program.py ROOT --check LIST

The program is the files of CMakeLists.txt's PORTALSIM_KERNELS: its helpers list, then
every kernels/*.cl in name order, joined by a newline (cmake/embed.cmake). With a mutation, TEXT must occur exactly once in FILE.
--check reads every mutation of LIST (FILE<TAB>TEXT<TAB>REPLACEMENT<TAB>WHY, # comments)
and fails, naming each line, where a TEXT no longer occurs exactly once in its FILE or a
line is malformed: a kernel edit that moved a mutation's text shows before a run (ctest
mutation_list), not an hour into it.
"""
import pathlib
import re
import sys


def kernel_texts(root: str) -> tuple[list[str], dict[str, str]]:
    cmake = (pathlib.Path(root) / "CMakeLists.txt").read_text(encoding="utf-8")
    # The helpers in their declared order, then every kernels/*.cl in name order (CMake's glob).
    helpers = re.search(r"set\(PORTALSIM_KERNEL_HELPERS\s+([^)]*)\)", cmake).group(1).split()
    stages = sorted(p.relative_to(root).as_posix() for p in (pathlib.Path(root) / "kernels").glob("*.cl"))
    files = helpers + stages
    return files, {f: (pathlib.Path(root) / f).read_text(encoding="utf-8") for f in files}


def check(root: str, listing: str) -> int:
    _, texts = kernel_texts(root)
    bad, n = 0, 0
    for line_no, line in enumerate(pathlib.Path(listing).read_text(encoding="utf-8").split("\n"), 1):
        if not line.strip() or line.startswith("#"):
            continue
        n += 1
        parts = line.split("\t")
        where = f"{listing}:{line_no} (mutation {n})"
        if len(parts) != 4 or not all(parts):
            print(f"{where}: want FILE<TAB>TEXT<TAB>REPLACEMENT<TAB>WHY, got {len(parts)} fields", file=sys.stderr)
            bad += 1
            continue
        file, old, new, _ = parts
        count = texts[file].count(old) if file in texts else -1
        if file not in texts:
            print(f"{where}: {file} is not a kernel file of PORTALSIM_KERNELS", file=sys.stderr)
            bad += 1
        elif count != 1:
            print(f"{where}: the text occurs {count} times in {file} (must be once): {old}", file=sys.stderr)
            bad += 1
        elif old == new:
            print(f"{where}: the replacement is the text itself", file=sys.stderr)
            bad += 1
    print(f"{n} mutations, {bad} to fix")
    return 1 if bad or n == 0 else 0


def main() -> int:
    if len(sys.argv) == 4 and sys.argv[2] == "--check":
        return check(sys.argv[1], sys.argv[3])
    root, out, *mutation = sys.argv[1:]
    files, texts = kernel_texts(root)
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
