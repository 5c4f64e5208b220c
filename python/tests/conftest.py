"""Shared fixtures: the shipped model, a bundled material, and the `experiments` binary the
equality tests compare with."""
import os
import pathlib
import shutil

import pytest

import deepbrdf

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def model():
    return deepbrdf.Model.load()


@pytest.fixture(scope="session")
def chrome():
    return deepbrdf.bundled("chrome")


@pytest.fixture(scope="session")
def experiments():
    """The `experiments` binary: $DEEPBRDF_EXPERIMENTS, else the release build of this checkout
    ($CARGO_TARGET_DIR or target/). Missing, the equality tests fail and say how to build it."""
    candidates = []
    if os.environ.get("DEEPBRDF_EXPERIMENTS"):
        candidates.append(pathlib.Path(os.environ["DEEPBRDF_EXPERIMENTS"]))
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    candidates.append(target / "release" / "experiments")
    found = shutil.which("experiments")
    for path in candidates + ([pathlib.Path(found)] if found else []):
        if path.is_file():
            return path
    pytest.fail(
        "no experiments binary at "
        + ", ".join(str(c) for c in candidates)
        + ": build it with `cargo build --release -p experiments` or set DEEPBRDF_EXPERIMENTS"
    )
