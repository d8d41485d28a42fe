"""The layering check (scripts/check_layers.py): clean on the repository, and it catches a
planted violation in a tree of its own; the committed module graph is the declared one."""
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "check_layers.py"


def run(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True)


def planted_tree(tmp_path, files):
    """A copy of the repository's declaration with the given source files."""
    (tmp_path / "src/microcobot").mkdir(parents=True)
    shutil.copy(ROOT / "src/microcobot/CMakeLists.txt", tmp_path / "src/microcobot/CMakeLists.txt")
    for rel, text in files.items():
        f = tmp_path / "src/microcobot" / rel
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(text)
    return tmp_path


def test_the_repository_keeps_its_layers():
    r = run()
    assert r.returncode == 0, r.stderr
    assert "every include within its layer" in r.stdout


def test_an_include_upwards_is_caught_naming_file_line_and_modules(tmp_path):
    root = planted_tree(tmp_path, {
        "core/ok.h": '#pragma once\n#include "microcobot/core/error.h"\n',
        "motion/pid.h": '#pragma once\n#include "microcobot/stickslip/actuator.h"\n'
                        '#include "microcobot/live/live_platform.h"\n',
    })
    r = run("--root", str(root))
    assert r.returncode == 1
    assert "src/microcobot/motion/pid.h:3: module 'motion' may not include 'live'" in r.stderr
    assert "stickslip" not in r.stderr.split("may not include")[1].split("(")[0]
    assert "1 include(s)" in r.stderr


def test_a_dependency_of_a_dependency_is_allowed_and_a_peer_is_not(tmp_path):
    # platform -> perception -> devices -> runtime: allowed; haptics -> tweezers: peers, refused.
    root = planted_tree(tmp_path, {
        "platform/p.cc": '#include "microcobot/runtime/spsc_ring.h"\n',
        "haptics/h.cc": '#include "microcobot/tweezers/teletweez.h"\n',
    })
    r = run("--root", str(root))
    assert r.returncode == 1
    assert "haptics/h.cc:1: module 'haptics' may not include 'tweezers'" in r.stderr
    assert "platform/p.cc" not in r.stderr


def test_a_folder_no_module_declares_is_caught(tmp_path):
    root = planted_tree(tmp_path, {"vendor/x.h": "#pragma once\n"})
    r = run("--root", str(root))
    assert r.returncode == 1
    assert "src/microcobot/vendor/: a folder that no mc_add_module() declares" in r.stderr


def test_a_dependency_declared_before_its_module_is_refused(tmp_path):
    (tmp_path / "src/microcobot").mkdir(parents=True)
    (tmp_path / "src/microcobot/CMakeLists.txt").write_text("mc_add_module(core)\nmc_add_module(a DEPS mc_b)\n")
    r = run("--root", str(tmp_path))
    assert r.returncode == 2
    assert "module 'a' depends on 'b', which is not declared before it" in r.stderr


def test_the_committed_module_graph_is_the_declared_one():
    r = run("--dot")
    assert r.returncode == 0
    committed = (ROOT / "docs/module-graph.dot").read_text()
    assert committed == r.stdout, "docs/module-graph.dot is stale: run `make graph`"
    svg = (ROOT / "docs/module-graph.svg").read_text()
    for line in r.stdout.splitlines():
        if line.strip().endswith(";") and "->" not in line and "=" not in line:
            assert f">{line.strip()[:-1]}</text>" in svg, f"{line.strip()} missing from docs/module-graph.svg"
