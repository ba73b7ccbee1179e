"""pytest set-up for the sph Python package: the package from the source
tree (python/), the library from SPH_LIBRARY (ctest points it at the
build's libsph.so)."""

import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))


@pytest.fixture
def scenes():
    """The shipped scenes' folder."""
    return ROOT / "scenes"
