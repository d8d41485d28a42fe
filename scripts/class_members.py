#!/usr/bin/env python3
"""Counts the data members a C++ class declares (its own, not its bases'), for the house rule
"no class with more than ~35 data members" (docs/architecture.md, Conventions).

    scripts/class_members.py src/microcobot/live/live_platform.h LivePlatform [FILE CLASS ...]

A member is a declaration at the class's own level that is not a function, a type, a `using`, a
`friend` or a static; `int a = 0, b = 0;` counts two. Comments and function bodies are ignored.
"""
import re
import sys


def count(path, cls):
    src = open(path, encoding="utf-8").read()
    m = re.search(r"\b(class|struct)\s+" + re.escape(cls) + r"\b[^;{]*\{", src)
    if not m:
        raise SystemExit(f"{path}: no class {cls}")
    i, depth, body = m.end(), 1, []
    while depth:
        c = src[i]
        depth += c == "{"
        depth -= c == "}"
        body.append(c)
        i += 1
    text = re.sub(r"//[^\n]*", "", "".join(body))
    flat, d = [], 0
    for c in text:  # the class's own level only: nested bodies dropped
        if c == "{":
            d += 1
            flat.append("{" if d == 1 else "")
        elif c == "}":
            d -= 1
            flat.append("}" if d == 0 else "")
        elif d == 0:
            flat.append(c)
    n = 0
    for stmt in "".join(flat).split(";"):
        s = re.sub(r"^(public|private|protected):\s*", "", " ".join(stmt.split()))
        if not s or s.startswith(("using", "friend", "static", "template", "enum", "struct", "class", "typedef")):
            continue
        if "(" in s.split("=")[0]:
            continue  # a function
        n += len(re.split(r",(?![^<]*>)", s))
    return n


if __name__ == "__main__":
    args = sys.argv[1:]
    if not args or len(args) % 2:
        raise SystemExit(__doc__)
    for path, cls in zip(args[::2], args[1::2]):
        print(f"{cls}: {count(path, cls)}")
