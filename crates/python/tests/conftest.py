"""Shared fixtures: the repository, and the command-line program to compare against."""

import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def repo() -> pathlib.Path:
    return REPO


@pytest.fixture(scope="session")
def binary() -> pathlib.Path:
    """The `piezocontact` program of this checkout (`PIEZOCONTACT_BIN`, else target/release,
    built if missing)."""
    path = pathlib.Path(os.environ.get("PIEZOCONTACT_BIN", REPO / "target" / "release" / "piezocontact"))
    if not path.exists():
        subprocess.run(["cargo", "build", "--release", "-p", "driver"], cwd=REPO, check=True)
    assert path.exists(), f"no program at {path}"
    return path


def csv_rows(path: pathlib.Path) -> list:
    """A CSV output's rows, each a dict by column name: the header's units in brackets taken
    off (`normal_force [mN]` is `normal_force`), as run.json's `units.columns` names them."""
    import csv

    with open(path, encoding="utf-8") as f:
        return [{k.split(" [")[0]: v for k, v in row.items()} for row in csv.DictReader(f)]
