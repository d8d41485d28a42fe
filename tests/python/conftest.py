"""Shared fixtures of the Python module's tests: the CLI (same library calls) for comparisons."""

import os
import subprocess

import pytest


@pytest.fixture(scope="session")
def cli():
    """Runs `microcobot ARGS...`; returns (exit code, stdout, stderr)."""
    path = os.environ.get("MC_CLI")
    if not path:
        pytest.skip("MC_CLI not set (run through ctest)")

    def run(*args):
        p = subprocess.run([path, *map(str, args)], capture_output=True, text=True, timeout=600)
        return p.returncode, p.stdout, p.stderr

    return run


def cli_error(stderr):
    """The one-line message of a failed CLI run, without its 'microcobot: error: ' prefix."""
    lines = [l for l in stderr.splitlines() if l.startswith("microcobot: error: ")]
    assert len(lines) == 1, stderr
    return lines[0][len("microcobot: error: "):]
