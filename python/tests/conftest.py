"""Shared fixtures: the demo data of the checkout and a library of its three meshes (ctest's, or built once per test
file)."""

import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("ECVPOSE_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DEMO_FRAME = str(SOURCE_DIR / "models" / "frame" / "000001")
DEMO_MESHES = str(SOURCE_DIR / "models" / "meshes")
DATA_DIR = pathlib.Path(os.environ.get("ECVPOSE_DATA_DIR", SOURCE_DIR.parent / "shared" / "data"))


@pytest.fixture(scope="module")
def demo_library_path(tmp_path_factory):
    """The library of models/meshes as the demo builds it: 40 views at 0.9 m. Under ctest, the one its demo_library
    fixture built once for every test (ECV_DEMO_LIBRARY), which tests read and do not change."""
    if "ECV_DEMO_LIBRARY" in os.environ:
        return pathlib.Path(os.environ["ECV_DEMO_LIBRARY"])
    import ecvpose  # here, not above: tests of the scripts (test_bop_dataset.py) run without the module built

    path = tmp_path_factory.mktemp("library") / "demo.sqlite"
    ecvpose.build_models(str(path), DEMO_MESHES, views=40, distance=0.9)
    return path


@pytest.fixture(scope="module")
def demo_library(demo_library_path):
    import ecvpose

    return ecvpose.ModelLibrary.open(str(demo_library_path))


@pytest.fixture(scope="module")
def demo_frame():
    import ecvpose

    return ecvpose.load_frame(DEMO_FRAME)
