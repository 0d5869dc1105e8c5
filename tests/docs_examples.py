#!/usr/bin/python3
"""Runs the command blocks of a Markdown guide and compares the output they show.

    docs_examples.py --portalsim BIN GUIDE.md [GUIDE.md ...]
    docs_examples.py --self-test --portalsim BIN GUIDE.md

Each fenced block of a guide declares what it is, and every block that holds a command
is run (docs/dev/testing.md, "Docs run as tests"):

- `console`: a terminal session. `$ ` starts a command, `> ` continues it, and the lines
  after it are the output it must print (stdout and stderr together). In an output line,
  `…` stands for any text on that line (times, rates, paths), and `(exit N)` alone on a
  line is the command's non-zero exit status.
- `sh`: commands whose output is not shown; they run as one script (`set -e`) and must
  exit 0.
- `python`: run by Debian's /usr/bin/python3; must exit 0.
- `pycon`: a Python session (`>>> `, `... `) and the values it shows, checked by Python's
  doctest (a shown `…` or `...` stands for any text); each block is a session of its own.
- `usage`: a synopsis. It is not run; every `--flag` it names must be in the `--help` of
  the `portalsim` subcommand it shows.
- `text`, `toml`, `json`, `csv`, `markdown`: data and printed text, not commands.

A block without a language is refused, so that nothing runnable is left out unseen.

An HTML comment just before a block changes how the test runs it, unseen by readers:
- `<!-- doctest: replace "A" "B" -->` runs the block with A replaced by B (smaller counts
  for long runs; A must occur in the block);
- `<!-- doctest: before COMMAND -->` runs COMMAND first (files an example needs);
- `<!-- doctest: covered by TEST -->` does not run the block, because ctest's TEST (named
  in CMakeLists.txt), or the repository's script TEST (`.ci/run`), runs the same commands
  (a Slurm cluster, installing as root).

All blocks of one guide run in order in one bash session, in an empty folder that holds
links to the repository's `scenarios/`, `tools/` and `bench/`, with the build's `portalsim` first on
the PATH and its Python package on PYTHONPATH. Uses cram (Debian python3-cram) to run the
session and compare its output.
"""
import argparse
import functools
import os
import re
import shutil
import subprocess
import sys
import tempfile

import cram

RUNNABLE = {"console", "sh", "python", "pycon", "usage"}
DATA = {"text", "toml", "json", "csv", "markdown"}
DIRECTIVE = re.compile(r"<!--\s*doctest:\s*(.*?)\s*-->")
INDENT = "  "


class DocError(Exception):
    pass


def blocks(path):
    """Yields (line, language, lines, directives) for each fenced block of a Markdown file."""
    with open(path, encoding="utf-8") as f:
        text = f.read().splitlines()
    pending = []
    i = 0
    while i < len(text):
        line = text[i]
        m = DIRECTIVE.fullmatch(line.strip())
        if m:
            pending.append(m.group(1))
            i += 1
            continue
        if line.startswith("```"):
            lang = line[3:].strip()
            start = i + 1
            body = []
            i += 1
            while i < len(text) and not text[i].startswith("```"):
                body.append(text[i])
                i += 1
            if i == len(text):
                raise DocError(f"{path}:{start}: code block never closed")
            yield start, lang, body, pending
            pending = []
        elif line.strip():
            if pending:
                raise DocError(f"{path}:{i + 1}: a doctest comment must come just before a code block")
        i += 1
    if pending:
        raise DocError(f"{path}: a doctest comment at the end, with no code block after it")


def parse_directives(path, line, directives, body):
    """Applies replace directives to body; returns (body, before commands, covering test)."""
    before, covered = [], None
    joined = "\n".join(body)
    for d in directives:
        m = re.fullmatch(r'replace\s+"((?:[^"\\]|\\.)*)"\s+"((?:[^"\\]|\\.)*)"', d)
        if m:
            old, new = (bytes(s, "utf-8").decode("unicode_escape") for s in m.groups())
            if old not in joined:
                raise DocError(f"{path}:{line}: doctest replace: {old!r} is not in the block")
            joined = joined.replace(old, new)
            continue
        m = re.fullmatch(r"before\s+(.+)", d)
        if m:
            before.append(m.group(1))
            continue
        m = re.fullmatch(r"covered by\s+(\S+)", d)
        if m:
            covered = m.group(1)
            continue
        raise DocError(f"{path}:{line}: unknown doctest comment {d!r}")
    return joined.split("\n") if body else [], before, covered


def glob_line(out):
    """An expected output line in cram's syntax: `…` becomes cram's glob."""
    if "…" not in out:
        return INDENT + out
    escaped = out.replace("\\", "\\\\").replace("*", "\\*").replace("?", "\\?")
    return INDENT + escaped.replace("…", "*") + " (glob)"


def hidden(command):
    """A command the reader does not see, whose output is not compared but must succeed."""
    return [f"{INDENT}$ ( {command} ) > \"$DOCTEST_LOG\" 2>&1 || {{ cat \"$DOCTEST_LOG\"; false; }}"]


def script(lines):
    """A block run as one script under set -e, its output shown only when it fails."""
    out = [f"{INDENT}$ ( set -e"]
    out += [f"{INDENT}> {l}" for l in lines]
    out.append(f"{INDENT}> ) > \"$DOCTEST_LOG\" 2>&1 || {{ cat \"$DOCTEST_LOG\"; false; }}")
    return out


def console(path, line, body):
    out = []
    seen_command = False
    for n, l in enumerate(body):
        if l.startswith("$ "):
            out.append(INDENT + l)
            seen_command = True
        elif l.startswith("> ") and seen_command:
            out.append(INDENT + l)
        elif not seen_command:
            raise DocError(f"{path}:{line + n}: a console block starts with a `$ ` command")
        else:
            m = re.fullmatch(r"\(exit (\d+)\)", l.strip())
            out.append(f"{INDENT}[{m.group(1)}]" if m else glob_line(l))
    return out


def pycon(path, line, body):
    """A Python session checked by doctest, its report shown only when it fails."""
    text = "\n".join(body).replace("…", "...") + "\n"
    return script([
        "/usr/bin/python3 - <<'DOCTEST_PYTHON'",
        "import doctest, sys",
        f"test = doctest.DocTestParser().get_doctest({text!r}, {{}}, {path!r}, {path!r}, {line})",
        "runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)",
        "runner.run(test)",
        "sys.exit(1 if runner.failures else 0)",
        "DOCTEST_PYTHON",
    ])


@functools.lru_cache(maxsize=None)
def subcommand_help(portalsim, words):
    r = subprocess.run([portalsim, *words, "--help"], capture_output=True, text=True)
    if r.returncode != 0:
        raise DocError(f"`portalsim {' '.join(words)} --help` failed: {r.stderr.strip()}")
    return r.stdout


def check_usage(path, line, body, portalsim):
    """Every --flag in a synopsis is in its subcommand's --help."""
    words = None
    for n, l in enumerate(body):
        m = re.match(r"\s*portalsim(?:\s+([a-z][a-z-]*))?", l)
        if m:
            words = (m.group(1),) if m.group(1) else ()
        if words is None:
            raise DocError(f"{path}:{line + n}: a usage block's first line is `portalsim ...`")
        text = subcommand_help(portalsim, words)
        for flag in re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", l):
            if not re.search(r"(?<![\w-])" + re.escape(flag) + r"(?![\w-])", text):
                raise DocError(f"{path}:{line + n}: {flag} is not an option of `portalsim {' '.join(words)}`")


def cram_lines(path, portalsim, repo, cmake_lists):
    """The guide as one cram session; usage blocks are checked on the way."""
    lines = []
    for line, lang, body, directives in blocks(path):
        if not lang:
            raise DocError(f"{path}:{line}: a code block without a language (one of {sorted(RUNNABLE | DATA)})")
        lang = lang.split()[0]
        if lang not in RUNNABLE | DATA:
            raise DocError(f"{path}:{line}: unknown code block language {lang!r} (one of {sorted(RUNNABLE | DATA)})")
        body, before, covered = parse_directives(path, line, directives, body)
        if covered:
            if f"NAME {covered} " not in cmake_lists and not os.path.isfile(os.path.join(repo, covered)):
                raise DocError(f"{path}:{line}: doctest covered by {covered}: neither a ctest test in "
                               "CMakeLists.txt nor a file of the repository")
            continue
        if lang in DATA:
            if before:
                raise DocError(f"{path}:{line}: doctest before on a {lang} block, which is not run")
            continue
        for b in before:
            lines += hidden(b)
        if lang == "usage":
            check_usage(path, line, body, portalsim)
        elif lang == "console":
            lines += console(path, line, body)
        elif lang == "sh":
            lines += script(body)
        elif lang == "python":
            lines += script(["/usr/bin/python3 - <<'DOCTEST_PYTHON'", *body, "DOCTEST_PYTHON"])
        elif lang == "pycon":
            lines += pycon(path, line, body)
    return lines


def run_guide(path, portalsim, repo, work):
    with open(os.path.join(repo, "CMakeLists.txt"), encoding="utf-8") as f:
        cmake_lists = f.read()
    lines = cram_lines(path, portalsim, repo, cmake_lists)
    if not lines:
        return []
    os.makedirs(work, exist_ok=True)
    for name in ("scenarios", "tools", "bench"):
        link = os.path.join(work, name)
        if not os.path.lexists(link):
            os.symlink(os.path.join(repo, name), link)
    env = os.environ.copy()
    env["PATH"] = os.path.dirname(os.path.abspath(portalsim)) + os.pathsep + env["PATH"]
    python_dir = os.path.join(os.path.dirname(os.path.abspath(portalsim)), "python")
    env["PYTHONPATH"] = python_dir + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env["DOCTEST_LOG"] = os.path.join(work, ".doctest.log")
    cwd = os.getcwd()
    os.chdir(work)
    try:
        encoded = [(l + "\n").encode("utf-8") for l in lines]
        _, _, diff = cram.test(encoded, shell="/bin/bash", env=env, testname=path.encode("utf-8"))
        return [d.decode("utf-8", "replace") for d in diff]
    finally:
        os.chdir(cwd)


def self_test(path, portalsim, repo):
    """The guide passes as written, and fails once one shown output line is edited."""
    with tempfile.TemporaryDirectory() as tmp:
        if run_guide(path, portalsim, repo, os.path.join(tmp, "asis")):
            raise DocError(f"self-test: {path} fails as written")
        with open(path, encoding="utf-8") as f:
            text = f.read().splitlines(True)
        edited = None
        for line, lang, body, _ in blocks(path):
            if lang == "console":
                for n, l in enumerate(body):
                    if not l.startswith(("$ ", "> ")) and l.strip() and "…" not in l and n > 0:
                        edited = line + n
                        break
            if edited:
                break
        if edited is None:
            raise DocError(f"self-test: {path} has no console output line to edit")
        text[edited] = text[edited].rstrip("\n") + " (edited)\n"
        copy = os.path.join(tmp, os.path.basename(path))
        with open(copy, "w", encoding="utf-8") as f:
            f.writelines(text)
        diff = run_guide(copy, portalsim, repo, os.path.join(tmp, "edited"))
        if not any("(edited)" in d for d in diff):
            raise DocError(f"self-test: editing {path}:{edited + 1} did not fail the guide")
        print(f"self-test: {path} passes as written and fails with line {edited + 1} edited")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--portalsim", required=True, help="the binary under test")
    ap.add_argument("--repo", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--work", help="folder to run in (default: a new temporary one, removed after)")
    ap.add_argument("--self-test", action="store_true")
    ap.add_argument("guides", nargs="+")
    a = ap.parse_args()
    try:
        if a.self_test:
            for g in a.guides:
                self_test(g, a.portalsim, a.repo)
            return 0
        failed = 0
        for g in a.guides:
            work = a.work or tempfile.mkdtemp(prefix="portalsim-doctest-")
            diff = run_guide(g, a.portalsim, a.repo, work)
            if diff:
                failed += 1
                sys.stdout.write("".join(diff))
                print(f"{g}: the output differs from the guide (- guide, + now); ran in {work}")
            else:
                if not a.work:
                    shutil.rmtree(work)
                print(f"{g}: every example runs as shown")
        print(f"{len(a.guides) - failed} passed, {failed} failed")
        return 1 if failed else 0
    except DocError as e:
        print(f"docs_examples: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
