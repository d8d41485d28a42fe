"""The documentation's own checks (ctest docs_pages): the README's first screen, the user pages free
of history, every tutorial tested and every example used, the reference generator failing on
what has no description (a planted CLI option, Python function and configuration key), and the
results page failing on a benchmark script's missing JSON.

Needs MC_CLI (the microcobot binary) and PYTHONPATH at the built module for the generator's tests.
"""

import importlib.util
import os
import re
import stat
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
spec = importlib.util.spec_from_file_location("gen_reference", ROOT / "scripts" / "docs" / "gen_reference.py")
gen = importlib.util.module_from_spec(spec)
spec.loader.exec_module(gen)


def user_pages():
    pages = [ROOT / "README.md"] + sorted(DOCS.rglob("*.md"))
    return [p for p in pages if "notes" not in p.relative_to(ROOT).parts]


def test_the_readme_says_what_it_is_for_whom_and_the_two_commands_on_its_first_screen():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 150, f"README.md has {len(lines)} lines (at most 150)"
    first = "\n".join(lines[:25])
    for needed in ("desktop micro-manipulation cobotic platform", "for labs", "make run", "make test",
                   "Design and Realization of a Desktop Micro-manipulation Cobotic Platform"):
        assert needed in first, f"README.md's first screen lacks '{needed}'"


def test_user_pages_carry_no_issue_numbers_dates_or_branch_names():
    history = re.compile(r"issue #|20[0-9]{2}-[01][0-9]-[0-3][0-9]|branch track")
    found = [f"{p.relative_to(ROOT)}:{i}: {line.strip()[:100]}"
             for p in user_pages() for i, line in enumerate(p.read_text().splitlines(), 1) if history.search(line)]
    assert not found, "history in user pages (it belongs in CHANGELOG.md or docs/notes/):\n" + "\n".join(found)


def test_every_tutorial_has_tested_blocks_and_every_example_is_shown_somewhere():
    for page in sorted((DOCS / "tutorials").glob("*.md")):
        assert "<!-- test" in page.read_text(), f"{page.name} has no tested block"
    text = "\n".join(p.read_text() for p in [ROOT / "README.md"] + sorted(DOCS.rglob("*.md")))
    for example in sorted((ROOT / "examples").rglob("*")):
        if example.is_file() and example.suffix in (".py", ".mjs"):
            rel = example.relative_to(ROOT).as_posix()
            assert rel in text, f"{rel} is not used by any page"


def test_every_page_is_in_the_navigation():
    nav = set(re.findall(r":\s*([\w/.-]+\.md)\s*$", (ROOT / "mkdocs.yml").read_text(), flags=re.M))
    generated = {"changelog.md", "license.md", "reference/cli.md", "reference/configuration.md",
                 "reference/python.md", "reference/telemetry.md", "reference/vendor.md", "reference/exit-codes.md"}
    pages = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md")}
    assert not pages - nav, f"pages not in mkdocs.yml's nav: {sorted(pages - nav)}"
    assert not nav - pages - generated, f"nav entries without a page: {sorted(nav - pages - generated)}"


def test_a_cli_option_without_a_description_fails_the_reference(tmp_path):
    fake = tmp_path / "microcobot"
    fake.write_text("""#!/bin/sh
if [ "$1" = "--version" ]; then echo "microcobot 0.0.0"; exit 0; fi
if [ "$1" = "thing" ]; then cat <<'EOF'
Do a thing
Usage: microcobot thing [OPTIONS]

Options:
  -h,--help                   Print this help message and exit
  --described FLOAT           Has its description
  --bare INT
EOF
exit 0; fi
cat <<'EOF'
microcobot - test
Usage: microcobot [OPTIONS] SUBCOMMAND

Options:
  -h,--help                   Print this help message and exit

Subcommands:
  thing                       Do a thing
EOF
""")
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    gen.problems.clear()
    text, count = gen.gen_cli(str(fake))
    assert count == {"commands": 1, "options": 2}
    assert "| `--described FLOAT` | Has its description |" in text
    assert gen.problems == ["CLI option `microcobot thing --bare INT` has no description"]


def test_the_cli_help_wraps_long_descriptions_onto_one_entry():
    _, _, sections = gen.parse_help("""A command
Usage: microcobot x [OPTIONS]

Options:
  --duration FLOAT:[0.01 - 3600]:FINITE
                              Longest simulated time [s]
                              (default 120)
""")
    assert sections["Options"] == [["--duration FLOAT:[0.01 - 3600]:FINITE", "Longest simulated time [s] (default 120)"]]


@pytest.mark.skipif(not os.environ.get("PYTHONPATH"), reason="needs the built module on PYTHONPATH")
def test_a_public_python_function_without_a_docstring_fails_the_reference():
    import microcobot
    from microcobot import dsp

    def undocumented(x):
        return x

    dsp.undocumented_for_the_test = undocumented
    try:
        gen.problems.clear()
        gen.gen_python(Path(microcobot.__file__).parent.parent)
        assert "Python function microcobot.dsp.undocumented_for_the_test has no docstring" in gen.problems
    finally:
        del dsp.undocumented_for_the_test


def test_keys_are_described_from_the_field_their_visit_names():
    structs = gen.scan_headers()
    # camera_params.h: `double read_noise_e = 10.0;  ///< temporal dark noise, rms electrons`
    assert "temporal dark noise" in structs["SensorParams"]["read_noise_e"].doc
    assert gen.unit_of("rho1_a_N_s_m") == "N·s/m" and gen.unit_of("slew_rate_V_s") == "V/s"
    assert gen.unit_of("max_speed_m_s") == "m/s" and gen.unit_of("dark_current_e_per_s") == "electrons/s"


@pytest.mark.skipif(not os.environ.get("MC_CLI"), reason="needs MC_CLI")
def test_the_list_of_undescribed_keys_only_shrinks(tmp_path):
    gen.problems.clear()
    _, stats = gen.gen_configuration(os.environ["MC_CLI"])
    listed = {l.strip() for l in (ROOT / "scripts" / "docs" / "undescribed_keys.txt").read_text().splitlines()
              if l.strip() and not l.startswith("#")}
    stale = sorted(listed - set(stats["undescribed"]))
    assert not stale, f"described now (or gone): remove them from scripts/docs/undescribed_keys.txt: {stale}"
    assert not gen.problems, gen.problems


def test_a_benchmark_script_without_its_json_fails_the_results_page(tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("gen_results", ROOT / "scripts" / "docs" / "gen_results.py")
    results = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(results)
    monkeypatch.setattr(results, "RESULTS", tmp_path)  # no JSON there
    with pytest.raises(SystemExit) as failed:
        results.script_tables()
    message = str(failed.value)
    assert "serve_bench.json is missing" in message, message
    assert "gen_results.py --run build/release/bench serve_bench" in message, message
