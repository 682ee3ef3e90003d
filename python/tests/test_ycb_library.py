"""scripts/build_ycb_library: textured YCB objects of ycb_objects, the YCB-Video ones moved into the frame of the
YCB-Video ground truth, named and numbered as YCB-Video's, the symmetric ones marked. Two objects at 2 views."""

import json
import os
import subprocess

import numpy as np
import pytest

from conftest import DATA_DIR, SOURCE_DIR

SCRIPT = SOURCE_DIR / "scripts" / "build_ycb_library"
OBJECTS = DATA_DIR / "ycb_objects"


def frame_file_rows():
    """to_ycbv_frame.txt: object name -> 4x4 object_from_mesh."""
    rows = {}
    for line in (OBJECTS / "to_ycbv_frame.txt").read_text().splitlines():
        fields = line.split()
        if not fields or fields[0].startswith("#"):
            continue
        values = [float(v) for v in fields[1:13]]
        pose = np.eye(4)
        pose[:3, :3] = np.reshape(values[:9], (3, 3))
        pose[:3, 3] = values[9:12]
        rows[fields[0]] = pose
    return rows


def run(*args):
    env = {**os.environ, "ECVPOSE": os.environ["ECVPOSE_CLI"], "ECVPOSE_DATA_DIR": str(DATA_DIR)}
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, env=env, timeout=240)


NO_OBJECTS = pytest.mark.skipif(not (OBJECTS / "to_ycbv_frame.txt").exists(), reason="no ycb_objects in the data")


@NO_OBJECTS
def test_named_objects_are_built_in_the_ycbv_frame_with_ycbv_ids_and_symmetry(tmp_path):
    library = tmp_path / "ycb.sqlite"
    built = run(SCRIPT, library, "--objects", "010_potted_meat_can,061_foam_brick", "--views", 2, "--threads", 1)
    assert built.returncode == 0, built.stderr
    listed = run(os.environ["ECVPOSE_CLI"], "modeldb", "list", "--json", "--db", library)
    assert listed.returncode == 0, listed.stderr
    models = {m["name"]: m for m in json.loads(listed.stdout)}
    assert sorted(models) == ["010_potted_meat_can", "061_foam_brick"]
    assert models["010_potted_meat_can"]["bop_obj_id"] == 9  # YCB-Video's class indices
    assert models["061_foam_brick"]["bop_obj_id"] == 21
    assert not models["010_potted_meat_can"]["symmetric"]
    assert models["061_foam_brick"]["symmetric"]
    frames = frame_file_rows()
    for name, model in models.items():
        assert np.allclose(np.array(model["object_from_mesh"]), frames[name], atol=1e-6), name
        assert model["views"] == 2
        assert model["mesh_path"] == str((OBJECTS / name / "textured.obj").resolve()), "the mesh file, not a copy"


@NO_OBJECTS
def test_an_unknown_object_is_named_and_nothing_is_built(tmp_path):
    library = tmp_path / "none.sqlite"
    refused = run(SCRIPT, library, "--objects", "010_potted_meat_can,999_no_such_object", "--views", 2)
    assert refused.returncode == 1
    assert "999_no_such_object" in refused.stderr
    assert not library.exists()
    bad_flag = run(SCRIPT, library, "--objects", "010_potted_meat_can", "--no-such-flag")
    assert bad_flag.returncode == 2
