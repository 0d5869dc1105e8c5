#!/usr/bin/env python3
"""Fails on a broken relative link or image in any Markdown file that git tracks.

A link `[text](path)`, an image `![alt](path)` or a reference `[name]: path` whose path is
relative must name a file or folder that exists, relative to the Markdown file; a
`path.md#anchor` or `#anchor` must name a heading of that page, as GitHub makes anchors
from headings (lower case, punctuation dropped, spaces as hyphens, -1, -2 for repeats).
Links in code blocks and code spans are not links; web addresses are not checked.

Usage: docs_links_check.py REPO_ROOT       (exit 1 and one line per broken link)
       docs_links_check.py --self-test     (checks the checker on pages it writes)
"""
import pathlib
import re
import subprocess
import sys
import tempfile

INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
FENCE = re.compile(r"^\s{0,3}(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(?:.+?)\1")


def slug(heading: str) -> str:
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text stays
    text = text.lower()
    text = re.sub(r"[^\w\- ]", "", text)  # \w keeps letters, digits and _ (Unicode too)
    return text.replace(" ", "-")


def prose_lines(text: str):
    """(line number, line with code spans blanked) for every line outside code fences."""
    fence = None
    for n, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if m:
            if fence is None:
                fence = m.group(1)
            elif m.group(1) == fence:
                fence = None
            continue
        if fence is None:
            yield n, CODE_SPAN.sub(lambda s: " " * len(s.group(0)), line)


def heading_texts(text: str):
    """Headings with their code spans kept (the anchor keeps a code span's text)."""
    fence = None
    for line in text.splitlines():
        m = FENCE.match(line)
        if m:
            fence = m.group(1) if fence is None else (None if m.group(1) == fence else fence)
            continue
        if fence is None:
            h = HEADING.match(line)
            if h:
                yield h.group(2)


def page_anchors(path: pathlib.Path, cache: dict) -> set:
    if path not in cache:
        seen = {}
        found = set()
        for text in heading_texts(path.read_text(encoding="utf-8")):
            base = slug(text)
            count = seen.get(base, 0)
            seen[base] = count + 1
            found.add(base if count == 0 else f"{base}-{count}")
        cache[path] = found
    return cache[path]


def check(root: pathlib.Path, files: list) -> list:
    problems = []
    cache = {}
    for rel in files:
        page = root / rel
        for n, line in prose_lines(page.read_text(encoding="utf-8")):
            targets = [m.group(1) for m in INLINE.finditer(line)]
            ref = REFERENCE.match(line)
            if ref:
                targets.append(ref.group(1))
            for target in targets:
                if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith("//"):
                    continue  # a web address or mailto:
                file_part, _, anchor = target.partition("#")
                if file_part.startswith("/"):
                    problems.append(f"{rel}:{n}: {target}: an absolute path (links must be relative)")
                    continue
                dest = (page.parent / file_part).resolve() if file_part else page.resolve()
                if not dest.exists():
                    problems.append(f"{rel}:{n}: {target}: no such file")
                    continue
                if anchor and dest.suffix == ".md" and anchor not in page_anchors(dest, cache):
                    problems.append(f"{rel}:{n}: {target}: no heading #{anchor} in {dest.relative_to(root)}")
    return problems


def tracked_markdown(root: pathlib.Path) -> list:
    out = subprocess.run(["git", "-C", str(root), "ls-files", "-z", "*.md"], capture_output=True, check=True)
    return sorted(p for p in out.stdout.decode().split("\0") if p and (root / p).is_file())


def self_test() -> int:
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        (root / "docs").mkdir()
        (root / "pic.png").write_bytes(b"")
        (root / "docs/a.md").write_text(
            "# Page A\n\n## The `data.h5` file, and more (yes)\n\n## Repeat\n\n## Repeat\n", encoding="utf-8")
        good = ("[a](docs/a.md) ![p](pic.png) [h](docs/a.md#page-a) [c](docs/a.md#the-datah5-file-and-more-yes)\n"
                "[r](docs/a.md#repeat-1) [self](#top) [web](https://example.org/x.md) `[no](missing.md)`\n"
                "# Top\n```\n[fenced](missing.md)\n```\n[ref]: docs/a.md\n")
        (root / "good.md").write_text(good, encoding="utf-8")
        bad = ("[x](missing.md)\n![y](docs/missing.png)\n[z](docs/a.md#no-such-heading)\n"
               "[w](#nothing)\n[v](/etc/passwd)\n[u](docs/a.md#repeat-2)\n[ref]: gone.md\n")
        (root / "bad.md").write_text(bad, encoding="utf-8")
        ok = check(root, ["good.md", "docs/a.md"])
        broken = check(root, ["bad.md"])
    if ok:
        print("self-test: good links reported broken:", *ok, sep="\n  ")
        return 1
    if len(broken) != 7:
        print(f"self-test: {len(broken)} of 7 broken links found:", *broken, sep="\n  ")
        return 1
    print("self-test passed")
    return 0


def main() -> int:
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    root = pathlib.Path(sys.argv[1]).resolve()
    files = tracked_markdown(root)
    problems = check(root, files)
    for p in problems:
        print(p)
    print(f"{len(files)} Markdown files, {len(problems)} broken links")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
