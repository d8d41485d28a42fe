"""`make run` then `make test` compiles each library once.

`make run` configures a fresh build tree without the tests, benchmarks, Python module and OpenCV
camera driver (Makefile, configure-run); `make test` then turns them on in the same tree. Whatever
those options add, they must not change how the libraries that `make run` built are compiled:
every library object of the first configuration keeps its compile command, and every unity batch
its content, after the second, and none is dropped (the OpenCV camera's plugin is a library of its own,
added beside them). Runs CMake's configure step only (no compilation)."""
import json
import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
RUN_OPTS = ["-DMC_BUILD_TESTS=OFF", "-DMC_BUILD_BENCH=OFF", "-DMC_BUILD_PYTHON=OFF", "-DMC_WITH_OPENCV=OFF"]
TEST_OPTS = ["-DMC_BUILD_TESTS=ON", "-DMC_BUILD_BENCH=ON", "-DMC_BUILD_PYTHON=ON", "-DMC_WITH_OPENCV=ON"]


def configure(build, opts):
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                    "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON", *opts], check=True, capture_output=True, text=True)
    commands = {}
    for c in json.loads((build / "compile_commands.json").read_text()):
        output = c["command"].split(" -o ", 1)[1].split()[0]
        source = pathlib.Path(c["file"])
        text = source.read_text() if "/Unity/" in c["file"] else ""
        commands[output] = (c["command"], text)
    return commands


def test_the_libraries_make_run_built_are_not_recompiled_by_make_test(tmp_path):
    build = tmp_path / "build"
    run = configure(build, RUN_OPTS)
    after = configure(build, TEST_OPTS)
    lib_objects = {o: v for o, v in run.items() if "CMakeFiles/mc_" in o}
    assert len(lib_objects) > 20, sorted(run)
    changed = [o for o, v in lib_objects.items() if o in after and after[o] != v]
    assert not changed, "recompiled by make test: " + ", ".join(sorted(changed)[:10])
    dropped = sorted(o for o in lib_objects if o not in after)
    assert not dropped, dropped
    assert any("CMakeFiles/mc_opencv_capture.dir/" in o for o in after), "make test builds the OpenCV camera's plugin"
