"""build_models: progress as it goes, a library the command line reads, failures named once the rest is built."""

import os
import subprocess

import pytest

import ecvpose
from conftest import DEMO_MESHES

VIEWS = 6  # enough views to store a model; recognition is tested on the demo library


def test_builds_with_progress_and_the_command_line_reads_the_library(tmp_path):
    db = str(tmp_path / "lib.sqlite")
    calls = []
    built = ecvpose.build_models(db, DEMO_MESHES, views=VIEWS, progress=lambda *call: calls.append(call))
    names = ["003_cracker_box", "004_sugar_box", "006_mustard_bottle"]
    assert sorted(built) == names
    assert [call for call in calls if call[0] == "004_sugar_box"] == [("004_sugar_box", v, VIEWS) for v in
                                                                     range(1, VIEWS + 1)]
    assert len(calls) == 3 * VIEWS

    library = ecvpose.ModelLibrary.open(db)
    assert sorted(m.name for m in library.models) == names
    for model in library.models:
        assert model.views == VIEWS and not model.symmetric
        assert 0.1 < model.diameter_m < 0.35  # YCB boxes and bottle: 19-27 cm

    listed = subprocess.run([os.environ["ECVPOSE_CLI"], "modeldb", "list", "--db", db], capture_output=True,
                            text=True, check=False)
    assert listed.returncode == 0, listed.stderr
    for name in names:
        assert name in listed.stdout
    version = subprocess.run([os.environ["ECVPOSE_CLI"], "--version"], capture_output=True, text=True, check=True)
    assert ecvpose.__version__ in version.stdout


def test_a_bad_mesh_is_named_and_the_others_are_built(tmp_path):
    bad = tmp_path / "broken.ply"
    bad.write_text("ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
                   "property float z\nend_header\n0 0 0\n")
    db = str(tmp_path / "lib.sqlite")
    sugar = os.path.join(DEMO_MESHES, "004_sugar_box")
    with pytest.raises(ecvpose.InputError) as error:
        ecvpose.build_models(db, [str(bad), sugar], views=VIEWS, symmetric=True)
    assert str(bad) in str(error.value) and "1 built" in str(error.value), str(error.value)
    [model] = ecvpose.ModelLibrary.open(db).models
    assert model.name == "004_sugar_box" and model.symmetric


def test_bad_build_arguments_are_named(tmp_path):
    db = str(tmp_path / "lib.sqlite")
    for name, kwargs in [("views", {"views": 0}), ("shading", {"shading": "flat"}), ("size", {"size": (0, 480)}),
                         ("camera", {"camera": [[1, 0], [0, 1]]}), ("name", {"name": "one"}),
                         ("threads", {"threads": 10**6}), ("threads", {"threads": -1}),
                         ("object_from_mesh", {"object_from_mesh": [[2, 0, 0, 0]] + [[0, 0, 0, 1]] * 3})]:
        with pytest.raises(ecvpose.InputError) as error:
            ecvpose.build_models(db, DEMO_MESHES, **kwargs)
        assert name in str(error.value), (name, str(error.value))
    assert not os.path.exists(db)  # arguments are checked before the library is created


def test_a_library_built_without_point_pairs_says_so_to_a_recognizer_that_wants_them(tmp_path):
    db = str(tmp_path / "lib.sqlite")
    sugar = os.path.join(DEMO_MESHES, "004_sugar_box")
    ecvpose.build_models(db, [sugar], views=VIEWS, point_pairs=False)
    library = ecvpose.ModelLibrary.open(db)
    assert ecvpose.Recognizer(library, hypotheses="context").point_pair_warnings == []  # the context needs none
    [warning] = ecvpose.Recognizer(library).point_pair_warnings  # point pairs are on by default
    assert "004_sugar_box" in warning and "--no-ppf" in warning, warning

    ecvpose.build_models(db, [sugar], views=VIEWS)  # built again, with them
    assert ecvpose.Recognizer(ecvpose.ModelLibrary.open(db), hypotheses="both").point_pair_warnings == []
