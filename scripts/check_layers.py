#!/usr/bin/env python3
"""The layering check, and the module graph drawn from the same declaration.

The allowed dependencies between the library's modules are declared once, by the DEPS of each
mc_add_module() in src/microcobot/CMakeLists.txt. A module may include the headers of the modules
its DEPS name and, transitively, of theirs (every module may use core). This script reads that
declaration and every #include "microcobot/<module>/..." under src/microcobot/<module>/, and
reports each include of a module the file's module may not use. (Tests, apps and bindings link
the whole library: a test of one module may build it through the layers above.)

  check_layers.py [--root DIR]          check; exit 0 when clean, 1 on violations, 2 on bad input
  check_layers.py --dot [--root DIR]    print the module graph (graphviz dot, transitive reduction)
"""
import argparse
import pathlib
import re
import sys

DECL = re.compile(r"mc_add_module\(\s*(\w+)([^)]*)\)", re.S)
INCLUDE = re.compile(r'^\s*#\s*include\s+"microcobot/(\w+)/[^"]+"', re.M)

def parse_layers(cmakelists: pathlib.Path) -> dict:
    """Module -> declared direct dependencies, in declaration order (bottom-up)."""
    layers = {}
    for name, rest in DECL.findall(cmakelists.read_text(encoding="utf-8")):
        deps_part = re.split(r"\b(?:LIBS)\b", rest)[0]
        deps = re.findall(r"\bmc_(\w+)", deps_part.split("DEPS", 1)[1]) if "DEPS" in deps_part else []
        for d in deps:
            if d not in layers:
                raise ValueError(f"{cmakelists}: module '{name}' depends on '{d}', which is not declared before it")
        layers[name] = deps if name == "core" else sorted(set(deps) | {"core"})
    if not layers:
        raise ValueError(f"{cmakelists}: no mc_add_module() found")
    return layers


def closure(layers: dict) -> dict:
    allowed = {}
    for m, deps in layers.items():  # bottom-up: the deps' closures are known
        s = set(deps)
        for d in deps:
            s |= allowed[d]
        allowed[m] = s
    return allowed


def violations(root: pathlib.Path, layers: dict) -> list:
    allowed = closure(layers)
    found = []
    base = root / "src/microcobot"
    for module in sorted(p.name for p in base.iterdir() if p.is_dir()):
        if module not in layers:
            if any((base / module).glob("*.[hc]*")):
                found.append(f"src/microcobot/{module}/: a folder that no mc_add_module() declares")
            continue
        ok = allowed[module] | {module}
        for f in sorted((base / module).rglob("*")):
            if f.suffix not in (".h", ".cc", ".hpp", ".cpp"):
                continue
            text = f.read_text(encoding="utf-8", errors="replace")
            for m in INCLUDE.finditer(text):
                used = m.group(1)
                if used not in ok:
                    line = text.count("\n", 0, m.start()) + 1
                    found.append(f"{f.relative_to(root)}:{line}: module '{module}' may not include "
                                 f"'{used}' (allowed: {', '.join(sorted(ok - {module}))})")
    return found


def dot(layers: dict) -> str:
    """The declared graph without the edges implied by others (transitive reduction)."""
    allowed = closure(layers)
    lines = ["digraph modules {", '  rankdir=BT; node [shape=box, fontname="Helvetica", fontsize=11];']
    for m, deps in layers.items():
        lines.append(f"  {m};")
    for m, deps in layers.items():
        direct = [d for d in deps if not any(d in allowed[o] for o in deps if o != d)]
        for d in sorted(direct):
            lines.append(f"  {m} -> {d};")
    lines.append("}")
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=str(pathlib.Path(__file__).resolve().parent.parent),
                    help="the repository's root (default: this script's)")
    ap.add_argument("--dot", action="store_true", help="print the module graph instead of checking")
    a = ap.parse_args()
    root = pathlib.Path(a.root)
    cm = root / "src/microcobot/CMakeLists.txt"
    try:
        layers = parse_layers(cm)
    except (OSError, ValueError, IndexError) as e:
        print(f"check_layers: {e}", file=sys.stderr)
        return 2
    if a.dot:
        sys.stdout.write(dot(layers))
        return 0
    found = violations(root, layers)
    for v in found:
        print(v, file=sys.stderr)
    if found:
        print(f"check_layers: {len(found)} include(s) break the layering declared in {cm.relative_to(root)}",
              file=sys.stderr)
        return 1
    print(f"check_layers: {len(layers)} modules, every include within its layer")
    return 0


if __name__ == "__main__":
    sys.exit(main())
