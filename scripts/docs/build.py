#!/usr/bin/python3
"""Builds the documentation site into build/docs/ (what `make docs` and the ctest `docs_build` run).

    scripts/docs/build.py --cli build/release/apps/microcobot/microcobot --python build/release/python

1. stages docs/ into build/docs-src/ with CHANGELOG.md and LICENSE as pages;
2. generates the reference pages from the program (scripts/docs/gen_reference.py --check: a CLI
   option, configuration key or public Python function without a description fails the build);
3. fills the results page's tables from the benchmarks' JSON (scripts/docs/gen_results.py);
4. runs Doxygen on the C++ public headers into api/cpp/;
5. runs `mkdocs build --strict` (a warning, a broken link fails) and fails on an orphan page (a
   Markdown page that is not in mkdocs.yml's nav).
Prints the time of each step.
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent


def step(name, t0):
    print(f"docs: {name} {time.monotonic() - t0:.1f} s", flush=True)
    return time.monotonic()


def nav_pages(config_text):
    return set(re.findall(r":\s*([\w/.-]+\.md)\s*$", config_text, flags=re.M))


def main():
    ap = argparse.ArgumentParser(description="Build the documentation site (build/docs/)")
    ap.add_argument("--cli", required=True, help="the microcobot binary")
    ap.add_argument("--python", required=True, help="the directory of the built Python package")
    ap.add_argument("--no-doxygen", action="store_true", help="leave the C++ API pages out")
    args = ap.parse_args()
    t_start = t0 = time.monotonic()
    stage = ROOT / "build" / "docs-src"
    site = ROOT / "build" / "docs"
    shutil.rmtree(stage, ignore_errors=True)
    shutil.copytree(ROOT / "docs", stage)
    changelog = (ROOT / "CHANGELOG.md").read_text()
    (stage / "changelog.md").write_text(changelog.replace("](docs/", "]("))
    license_text = (ROOT / "LICENSE").read_text()
    notices = (ROOT / "THIRD_PARTY_NOTICES.md").read_text().split("\n", 1)[1].replace("](docs/", "](")
    (stage / "license.md").write_text(
        "# License\n\nmicrocobot is licensed under the Apache License, Version 2.0 "
        "(SPDX: `Apache-2.0`), the file `LICENSE` below. The web libraries embedded in the program "
        "keep their own licenses (Third-party notices).\n\n"
        "## Third-party notices\n" + notices + "\n## Apache License 2.0\n\n```text\n" + license_text + "```\n")
    t0 = step("staged", t0)

    subprocess.run([sys.executable, str(HERE / "gen_reference.py"), "--cli", args.cli, "--python", args.python,
                    "--out", str(stage / "reference"), "--check"], check=True)
    t0 = step("reference generated", t0)
    subprocess.run([sys.executable, str(HERE / "gen_results.py"), "--page", str(stage / "benchmarks.md")], check=True)
    t0 = step("results tables generated", t0)

    if not args.no_doxygen:
        out = stage / "api" / "cpp"
        out.mkdir(parents=True)
        version = subprocess.run([args.cli, "--version"], capture_output=True, text=True, check=True).stdout.split()[-1]
        env = dict(os.environ, MC_SOURCE_DIR=str(ROOT), MC_DOXYGEN_OUT=str(out), MC_VERSION=version)
        r = subprocess.run(["doxygen", str(HERE / "Doxyfile")], env=env, capture_output=True, text=True)
        if r.returncode != 0 or not (out / "index.html").exists():
            sys.stderr.write(r.stdout + r.stderr)
            sys.exit("docs: doxygen failed")
        t0 = step("doxygen", t0)
    else:
        (stage / "api" / "cpp").mkdir(parents=True)
        (stage / "api" / "cpp" / "index.html").write_text("<p>Built without --no-doxygen: the C++ API.</p>\n")

    config = (ROOT / "mkdocs.yml").read_text()
    in_nav = nav_pages(config)
    pages = {p.relative_to(stage).as_posix() for p in stage.rglob("*.md") if not p.relative_to(stage).as_posix().startswith("api/")}
    orphans = sorted(pages - in_nav)
    missing = sorted(in_nav - pages)
    if orphans or missing:
        for p in orphans:
            print(f"docs: orphan page (not in mkdocs.yml's nav): {p}", file=sys.stderr)
        for p in missing:
            print(f"docs: mkdocs.yml's nav names a missing page: {p}", file=sys.stderr)
        sys.exit(1)

    shutil.rmtree(site, ignore_errors=True)
    r = subprocess.run(["/usr/bin/python3", "-m", "mkdocs", "build", "--strict", "-f", str(ROOT / "mkdocs.yml")],
                       cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       env=dict(os.environ, NO_COLOR="1"))
    problems = [l for l in r.stdout.splitlines() if not l.startswith("INFO") and l.strip()]
    sys.stderr.write("".join(l + "\n" for l in problems))
    if r.returncode != 0 or any(re.search(r"WARNING|ERROR", l) for l in problems):
        sys.exit("docs: mkdocs build --strict failed")
    t0 = step("mkdocs build --strict", t0)
    print(f"docs: {site}/index.html ({len(pages)} pages) in {time.monotonic() - t_start:.1f} s")


if __name__ == "__main__":
    main()
