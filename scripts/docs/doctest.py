#!/usr/bin/python3
"""Runs the documentation's tested blocks, so that a page cannot show a command that no longer works.

    scripts/docs/doctest.py --cli build/release/apps/microcobot/microcobot --python build/release/python \
        [PAGE.md ...] [--list] [--keep] [--show]

A block is tested when the line before its fence is an HTML comment (invisible on the site):

    <!-- test -->                         run it as it is
    <!-- test: replace "--batch 50" "--batch 2"; timeout=120 -->
                                          run it with the short settings of `make test`

`sh` blocks run in bash (`set -euo pipefail`), `python` blocks in /usr/bin/python3. The blocks of a
page run in order in one fresh directory (they share its files), with `microcobot` (the --cli
binary) and `python3` (Debian's) first on PATH, PYTHONPATH at the built module, and `examples/`
, `scenes/` and `scripts/` linked from the source tree. A block that exits non-zero fails the page; what a
block left running in the background (`microcobot serve ... &`) is stopped at the page's end.
Default pages: docs/getting-started/*.md and docs/tutorials/*.md.
"""

import argparse
import os
import re
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BLOCK = re.compile(r"^<!--\s*test(?::(?P<opts>.*?))?\s*-->\s*\n```(?P<lang>\w+)[^\n]*\n(?P<body>.*?)^```\s*$",
                   re.M | re.S)


def blocks(page):
    text = page.read_text()
    for m in BLOCK.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        opts = {"replace": [], "timeout": 300}
        for part in (m.group("opts") or "").split(";"):
            part = part.strip()
            if not part:
                continue
            if part.startswith("replace"):
                args = shlex.split(part[len("replace"):])
                if len(args) != 2:
                    sys.exit(f"{page}:{line}: replace takes two quoted strings")
                opts["replace"].append(tuple(args))
            elif part.startswith("timeout="):
                opts["timeout"] = float(part.split("=", 1)[1])
            else:
                sys.exit(f"{page}:{line}: unknown test option '{part}'")
        body = m.group("body")
        for old, new in opts["replace"]:
            if old not in body:
                sys.exit(f"{page}:{line}: replace: '{old}' is not in the block")
            body = body.replace(old, new)
        yield line, m.group("lang"), body, opts


def run_page(page, cli, python_dir, keep, show=False):
    work = Path(tempfile.mkdtemp(prefix="mc-doctest-"))
    bindir = work / ".bin"
    bindir.mkdir()
    (bindir / "microcobot").symlink_to(Path(cli).resolve())
    (bindir / "python3").symlink_to("/usr/bin/python3")
    for d in ("examples", "scenes", "scripts"):
        (work / d).symlink_to(ROOT / d)
    env = dict(os.environ, PATH=f"{bindir}:/usr/local/bin:/usr/bin:/bin",
               PYTHONPATH=str(Path(python_dir).resolve()), MC_DOCTEST="1", MPLBACKEND="Agg")
    env.pop("PYTHONHOME", None)
    groups, failures, n = [], 0, 0
    t_page = time.monotonic()
    try:
        for line, lang, body, opts in blocks(page):
            n += 1
            if lang in ("sh", "bash", "console"):
                cmd = ["bash", "-euo", "pipefail", "-c", body]
            elif lang == "python":
                script = work / f".block_{line}.py"
                script.write_text(body)
                cmd = ["/usr/bin/python3", str(script)]
            else:
                sys.exit(f"{page}:{line}: a tested block must be sh or python, not {lang}")
            t0 = time.monotonic()
            proc = subprocess.Popen(cmd, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                    text=True, start_new_session=True)
            groups.append(proc.pid)
            try:
                out, _ = proc.communicate(timeout=opts["timeout"])
                rc = proc.returncode
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                out, rc = proc.communicate()[0], f"timeout after {opts['timeout']:.0f} s"
            dt = time.monotonic() - t0
            rel = page.relative_to(ROOT) if page.is_relative_to(ROOT) else page
            if rc != 0:
                failures += 1
                print(f"FAIL {rel}:{line} ({lang}, {dt:.1f} s): exit {rc}\n{out}", flush=True)
            else:
                print(f"ok   {rel}:{line} ({lang}, {dt:.1f} s)", flush=True)
                if show:
                    print(out, flush=True)
    finally:
        for pgid in groups:  # what the blocks left running in the background
            try:
                os.killpg(pgid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        time.sleep(0.2)
        for pgid in groups:
            try:
                os.killpg(pgid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        if keep:
            print(f"     kept {work}")
        else:
            subprocess.run(["rm", "-rf", str(work)])
    return n, failures, time.monotonic() - t_page


def main():
    ap = argparse.ArgumentParser(description="Run the documentation's tested blocks")
    ap.add_argument("--cli", required=True, help="the microcobot binary")
    ap.add_argument("--python", required=True, help="the directory of the built Python package")
    ap.add_argument("--keep", action="store_true", help="keep each page's working directory")
    ap.add_argument("--list", action="store_true", help="list the tested blocks and exit")
    ap.add_argument("--show", action="store_true", help="print each block's output (to update a page's)")
    ap.add_argument("pages", nargs="*", type=Path)
    args = ap.parse_args()
    pages = [p.resolve() for p in args.pages] or sorted((ROOT / "docs" / "getting-started").glob("*.md")) + \
        sorted((ROOT / "docs" / "tutorials").glob("*.md"))
    if args.list:
        for p in pages:
            for line, lang, body, _ in blocks(p):
                print(f"{p.relative_to(ROOT)}:{line} {lang}: {body.splitlines()[0] if body else ''}")
        return 0
    total_blocks, total_fail, t0 = 0, 0, time.monotonic()
    for p in pages:
        n, f, dt = run_page(p, args.cli, args.python, args.keep, args.show)
        total_blocks += n
        total_fail += f
    print(f"doctest: {total_blocks} blocks in {len(pages)} pages, {total_fail} failed, {time.monotonic() - t0:.1f} s")
    return 1 if total_fail else 0


if __name__ == "__main__":
    sys.exit(main())
