#!/usr/bin/env python3
"""Fails when a function under host/ is over 150 lines, unless it is a declarative registry.

A long function is cut into named steps; only a table that declares entries one after another
(no logic of its own) may run longer, and each such exception is listed in ALLOWED with why.

A body is the outermost brace block that is not a namespace, extern "C", class, struct,
union or enum body: a free function, a member function defined in its class, or an
initializer at namespace or class scope. Lambdas count toward the function that holds them.
Its length is counted from the line of its opening brace to the line of its closing one.
"""
import pathlib
import re
import sys

LIMIT = 150
# (file, name) -> why it may be longer than LIMIT
ALLOWED = {
    ("host/plan/knobs.cpp", "declare"): "the knob registry: one declaration per knob, no logic",
    ("host/plan/tolerance.h", "kTolerances"): "the tolerance table: one row per model, tier and output",
}
TYPE_HEAD = re.compile(r"(^|[\s>])(class|struct|union|enum)\b[^()=]*$")
NAMESPACE_HEAD = re.compile(r"(^|\s)(namespace\b[\w:\s]*|extern\s*\"C\"\s*)$")
NAME = re.compile(r"((?:[~\w]+::)*(?:operator\s*(?:\(\)|[^\s(]+)|[~\w]+))\s*\(")


def strip(text: str) -> str:
    """Blanks comments, string and character literals and preprocessor lines, keeping newlines."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            # a preprocessor line, with its continuations
            while i < n and not (text[i] == "\n" and text[i - 1] != "\\"):
                out.append("\n" if text[i] == "\n" else " ")
                i += 1
            continue
        if c == "/" and text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
            continue
        if c == "/" and text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
            continue
        raw = re.match(r'(?:u8|u|U|L)?R"([^(\s]*)\(', text[i:i + 40]) if c in 'uULR' else None
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = text.find(")" + raw.group(1) + '"', i + raw.end())
            j = n if end < 0 else end + len(raw.group(1)) + 2
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2:j]))
            i = j
            continue
        if c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # a digit separator: 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (min(j, n) - i - 1) + c)
            i = j + 1
            continue
        out.append(c)
        line_start = c == "\n" or (line_start and c in " \t")
        i += 1
    return "".join(out)


def bodies(text: str):
    """Yields (first line, last line, head) for each outermost body of text."""
    code = strip(text)
    stack = []  # "scope" for namespace and type bodies, "body" for anything else
    head_start = 0
    line = 1
    open_line = 0
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c in ";":
            if all(k == "scope" for k in stack):
                head_start = i + 1
        elif c == "{":
            head = " ".join(code[head_start:i].split())
            if all(k == "scope" for k in stack):
                if NAMESPACE_HEAD.search(head) or TYPE_HEAD.search(head):
                    stack.append("scope")
                    head_start = i + 1
                else:
                    stack.append("body")
                    open_line, open_head = line, head
            else:
                stack.append("body")
        elif c == "}":
            kind = stack.pop() if stack else "scope"
            if kind == "body" and all(k == "scope" for k in stack):
                yield open_line, line, open_head
            if all(k == "scope" for k in stack):
                head_start = i + 1
        elif c == ":" and all(k == "scope" for k in stack):
            # an access specifier ends a head: "public:" but not "::" or a constructor's ": x(1)"
            prev = code[head_start:i].split()
            if prev and prev[-1] in ("public", "private", "protected") and not code.startswith("::", i):
                head_start = i + 1


def name_of(head: str) -> str:
    head = re.sub(r"\)\s*:\s.*$", ")", head)  # a constructor's initializer list
    found = NAME.findall(head.split("=")[0] if "(" not in head.split("=")[0] else head)
    if found:
        return found[0].split("::")[-1]
    words = re.findall(r"\w+", head.split("=")[0])
    return words[-1] if words else head


def problems(root: pathlib.Path) -> list[str]:
    out = []
    used = set()
    host = root / "host"
    for path in sorted(host.rglob("*")):
        if path.suffix not in (".h", ".cpp") or not path.is_file():
            continue
        rel = path.relative_to(root).as_posix()
        for first, last, head in bodies(path.read_text(encoding="utf-8")):
            length = last - first + 1
            if length > LIMIT and (rel, name_of(head)) in ALLOWED:
                used.add((rel, name_of(head)))
            elif length > LIMIT:
                out.append(f"{rel}:{first}: {name_of(head)} is {length} lines (limit {LIMIT}): "
                           "cut it into named steps, or add it to ALLOWED in "
                           "tests/function_length_check.py if it is a declarative registry")
    for rel, name in sorted(set(ALLOWED) - used):
        out.append(f"{rel}: {name} is in ALLOWED but no longer over {LIMIT} lines (or gone): remove it from ALLOWED")
    return out


def self_test() -> list[str]:
    body = "\n".join(f"  x += {k};" for k in range(LIMIT))
    sample = (f'namespace a {{\nstruct S {{\n  int f() {{\n{body}\n    auto l = [] {{ return "}}"; }};\n  }}\n}};\n'
              "// } a brace in a comment\n"
              f"int g(int y) {{\n  return y;\n}}\n}}\n")
    found = [(first, last - first + 1, name_of(head)) for first, last, head in bodies(sample)]
    expected = [(3, LIMIT + 3, "f"), (LIMIT + 8, 3, "g")]
    return [] if found == expected else [f"self test: found {found}, expected {expected}"]


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    found = self_test() + problems(root)
    for p in found:
        print(p)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
