#!/usr/bin/python3
"""How much a fresh Debian 12 machine downloads and installs for scripts/install-deps.sh.

Usage: /usr/bin/python3 scripts/package_footprint.py [run|test]

Reads the package lists of scripts/install-deps.sh (RUN_PACKAGES; with `test`, TEST_PACKAGES too),
follows their Depends and Pre-Depends in this machine's apt cache (python3-apt), leaves out what a
minimal Debian 12 already has (priority required or important), and prints the number of
packages, the download and the installed size. Nothing is installed or downloaded: the figures
come from the package index, so they hold on a machine that already has the packages.
"""
import re
import sys

import apt_pkg


def listed(script, names):
    out = []
    for name in names:
        block = re.search(name + r"=\((.*?)\n\)", script, re.S).group(1)
        for line in block.splitlines():
            out += line.split("#")[0].split()
    return out


def main():
    which = sys.argv[1] if len(sys.argv) > 1 else "test"
    if which not in ("run", "test"):
        sys.exit(f"package_footprint: '{which}' must be run or test")
    script = open("scripts/install-deps.sh").read()
    names = listed(script, ["RUN_PACKAGES"] + (["TEST_PACKAGES"] if which == "test" else []))
    apt_pkg.init()
    cache = apt_pkg.Cache(None)
    dep = apt_pkg.DepCache(cache)
    seen, todo = {}, list(names)
    while todo:
        n = todo.pop()
        if n in seen:
            continue
        try:
            pkg = cache[n]
        except KeyError:  # a virtual package: its first provider
            prov = [p for p in cache.packages if any(pv[0] == n for pv in (p.provides_list or []))]
            if not prov:
                continue
            pkg = prov[0]
            n = pkg.name
            if n in seen:
                continue
        ver = dep.get_candidate_ver(pkg)
        if ver is None:
            continue
        seen[n] = ver
        for kind in ("Depends", "PreDepends"):
            for group in ver.depends_list.get(kind, []):
                todo.append(group[0].target_pkg.name)
    extra = {n: v for n, v in seen.items() if v.priority_str not in ("required", "important")}
    download = sum(v.size for v in extra.values())
    installed = sum(v.installed_size for v in extra.values())
    print(f"{which}: {len(names)} listed, {len(extra)} packages beyond a minimal Debian 12, "
          f"download {download / 1e6:.0f} MB, installed {installed / 1e6:.0f} MB")
    big = sorted(extra.items(), key=lambda kv: -kv[1].size)[:6]
    print("largest: " + ", ".join(f"{n} {v.size / 1e6:.0f} MB" for n, v in big))


if __name__ == "__main__":
    main()
