"""Shared fixtures: the command line to compare with, and the repository's shipped data."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
COMMA2K19 = REPO / "examples" / "comma2k19"


def _binary() -> pathlib.Path:
    if "ACCELCAL_BIN" in os.environ:
        return pathlib.Path(os.environ["ACCELCAL_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "release" / "accelcal"


@pytest.fixture(scope="session")
def cli():
    """Runs the `accelcal` binary (`cargo build --release` builds it; ACCELCAL_BIN names another)
    and returns the completed process; a missing binary fails the test, it is not skipped."""
    binary = _binary()
    if not binary.is_file():
        pytest.fail(f"{binary} not found: build it with `cargo build --release` or set ACCELCAL_BIN")

    def run(*args, check=True):
        done = subprocess.run(
            [str(binary), *map(str, args)], capture_output=True, text=True, stdin=subprocess.DEVNULL
        )
        if check and done.returncode != 0:
            raise AssertionError(f"accelcal {' '.join(map(str, args))}: {done.stderr}")
        return done

    return run
