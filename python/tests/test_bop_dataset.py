"""scripts/make_bop_dataset: the YCB-Video and LM-O subsets of the shared data in BOP's layout, checked against their
sources and against geometry computed here. Needs neither the C++ build nor the demo library."""

import importlib.machinery
import importlib.util
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import DATA_DIR, SOURCE_DIR

SCRIPT = SOURCE_DIR / "scripts" / "make_bop_dataset"
YCBV = DATA_DIR / "ycbv_subset"
LMO = DATA_DIR / "lmo_subset"
# ycbv_subset/SOURCE.md, "Objects per video", as YCB-Video class indices (the BOP obj_ids).
YCBV_OBJECTS = {0: {8, 14, 21}, 1: {1, 2, 3, 5}, 2: {5, 7, 9, 10, 16, 18}}
YCBV_NAMES = {1: "002_master_chef_can", 4: "005_tomato_soup_can", 6: "007_tuna_fish_can", 13: "024_bowl",
              18: "040_large_marker", 21: "061_foam_brick"}


def run(*args, data_dir=DATA_DIR):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "ECVPOSE_DATA_DIR": str(data_dir)})


def load(path):
    with open(path) as file:
        return json.load(file)


@pytest.fixture(scope="module")
def ycbv(tmp_path_factory):
    out = tmp_path_factory.mktemp("bop") / "ycbv"
    made = run("ycbv", out)
    assert made.returncode == 0, made.stderr
    return out


@pytest.fixture(scope="module")
def lmo(tmp_path_factory):
    out = tmp_path_factory.mktemp("bop") / "lmo"
    made = run("lmo", out)
    assert made.returncode == 0, made.stderr
    return out


def read_png16(path):
    """The script's PNG reader (no imaging package is required)."""
    sys.dont_write_bytecode, before = True, sys.dont_write_bytecode
    try:
        loader = importlib.machinery.SourceFileLoader("make_bop_dataset", str(SCRIPT))
        module = importlib.util.module_from_spec(importlib.util.spec_from_loader(loader.name, loader))
        loader.exec_module(module)
    finally:
        sys.dont_write_bytecode = before
    return module.read_png16(path)


def model_vertices(obj_id):
    """The vertices of the model's textured_simple.obj, mm."""
    with open(YCBV / "models" / YCBV_NAMES[obj_id] / "textured_simple.obj") as file:
        return 1000.0 * np.array([line.split()[1:4] for line in file if line.startswith("v ")], float)


def squared_distances(a, b):
    """|a_i - b_j|^2 for every pair (rows of a, rows of b); float32, enough for millimetres at this size."""
    a, b = a.astype(np.float32), b.astype(np.float32)
    squared = -2.0 * a @ b.T
    squared += (a * a).sum(1)[:, None]
    squared += (b * b).sum(1)[None, :]
    return np.maximum(squared, 0.0)


def nearest(queries, points):
    """Distance from each query to its nearest point, by brute force."""
    return np.sqrt(np.concatenate([squared_distances(part, points).min(1)
                                   for part in np.array_split(queries, max(1, len(queries) // 1000))]))


def turned(points, axis, offset, angle):
    """Points turned by `angle` about the line through `offset` along `axis`: in the plane across the axis."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    q = points - offset
    along = np.outer(q @ axis, axis)
    across = q - along
    return offset + along + np.cos(angle) * across + np.sin(angle) * np.cross(axis, across)


def test_ycbv_has_three_scenes_of_ten_images_with_the_objects_of_each_video(ycbv):
    assert sorted(p.name for p in (ycbv / "test").iterdir()) == ["000000", "000001", "000002"]
    images = 0
    for scene_id, objects in YCBV_OBJECTS.items():
        scene = ycbv / "test" / f"{scene_id:06d}"
        gt, camera = load(scene / "scene_gt.json"), load(scene / "scene_camera.json")
        names = sorted(f"{int(key):06d}.png" for key in gt)
        assert sorted(os.listdir(scene / "rgb")) == sorted(os.listdir(scene / "depth")) == names
        assert list(camera) == list(gt) and [int(key) for key in gt] == list(range(1, 20, 2))
        assert not (scene / "scene_gt_info.json").exists()
        for entries in gt.values():
            assert sorted(o["obj_id"] for o in entries) == sorted(objects)
        images += len(gt)
    assert images == 30


def test_ycbv_poses_are_the_source_poses_in_millimetres(ycbv):
    # derived/gt_0002.txt, frame 19, 036_wood_block: r11..r33 tx ty tz (metres), the numbers of its meta.mat's poses.
    with open(YCBV / "derived" / "gt_0002.txt") as file:
        row = next(line.split() for line in file if line.startswith("000019 16 036_wood_block"))
    entry = next(o for o in load(ycbv / "test" / "000002" / "scene_gt.json")["19"] if o["obj_id"] == 16)
    assert entry["cam_R_m2c"] == pytest.approx([float(v) for v in row[3:12]], abs=1e-9)
    assert entry["cam_t_m2c"] == pytest.approx([1000.0 * float(v) for v in row[12:15]], abs=1e-6)
    assert entry["cam_t_m2c"][2] == pytest.approx(1088.65108, abs=1e-6)  # 0002/000019-meta.mat poses[2, 3, 4], m


def test_ycbv_camera_and_targets(ycbv):
    camera = load(ycbv / "camera.json")
    assert camera == {"cx": 312.9869, "cy": 241.3109, "depth_scale": 0.1, "fx": 1066.778, "fy": 1067.487,
                      "height": 480, "width": 640}
    targets = load(ycbv / "test_targets_bop19.json")
    assert len(targets) == 130  # 10 images x (3 + 4 + 6) objects
    keys = [(t["scene_id"], t["im_id"], t["obj_id"]) for t in targets]
    assert keys == sorted(keys) and len(set(keys)) == 130
    assert {t["inst_count"] for t in targets} == {1}
    assert {(t["scene_id"], t["obj_id"]) for t in targets} == {(s, o) for s, ids in YCBV_OBJECTS.items() for o in ids}


def test_ycbv_depth_at_an_object_times_depth_scale_is_its_distance(ycbv):
    for scene_id, image_id, obj_id in [(2, 1, 18), (0, 19, 21)]:  # the marker, the foam brick: thin at their origin
        scene = ycbv / "test" / f"{scene_id:06d}"
        camera = load(scene / "scene_camera.json")[str(image_id)]
        t = next(o["cam_t_m2c"] for o in load(scene / "scene_gt.json")[str(image_id)] if o["obj_id"] == obj_id)
        k = camera["cam_K"]
        u, v = round(k[0] * t[0] / t[2] + k[2]), round(k[4] * t[1] / t[2] + k[5])
        depth = read_png16(scene / "depth" / f"{image_id:06d}.png")
        assert depth[v, u] * camera["depth_scale"] == pytest.approx(t[2], abs=50.0)


def test_ycbv_diameters_and_bounding_boxes(ycbv):
    info = load(ycbv / "models" / "models_info.json")
    assert sorted(map(int, info)) == [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 13, 14, 15, 16, 18, 21]
    for obj_id in (6, 18, 21):
        points = model_vertices(obj_id)
        farthest = max(np.sqrt(squared_distances(part, points).max()) for part in np.array_split(points, 8))
        assert info[str(obj_id)]["diameter"] == pytest.approx(farthest, abs=1.0)
        assert [info[str(obj_id)][f"min_{c}"] for c in "xyz"] == pytest.approx(points.min(0), abs=0.01)
        assert [info[str(obj_id)][f"size_{c}"] for c in "xyz"] == pytest.approx(np.ptp(points, 0), abs=0.01)


def test_ycbv_continuous_symmetries_turn_each_model_onto_itself_and_a_wrong_axis_does_not(ycbv):
    info = load(ycbv / "models" / "models_info.json")
    symmetric = {int(key) for key, model in info.items() if "symmetries_continuous" in model}
    assert symmetric == {1, 4, 6, 13, 18}
    assert not any("symmetries_discrete" in model for model in info.values())
    for obj_id in sorted(symmetric):
        (symmetry,) = info[str(obj_id)]["symmetries_continuous"]
        points, tolerance = model_vertices(obj_id), 0.05 * info[str(obj_id)]["diameter"]
        assert np.linalg.norm(symmetry["axis"]) == pytest.approx(1.0, abs=1e-5)
        moved = turned(points[::2], symmetry["axis"], symmetry["offset"], 1.0)  # an angle the script does not try
        assert nearest(moved, points).max() < tolerance, YCBV_NAMES[obj_id]
        if obj_id == 1:  # the master chef can: an axis across it, or the right one moved aside, fails
            across = np.cross(symmetry["axis"], [1.0, 0.0, 0.0])
            across /= np.linalg.norm(across)
            assert nearest(turned(points[::2], across, symmetry["offset"], 1.0), points).max() > tolerance
            aside = np.array(symmetry["offset"]) + 2.0 * tolerance * across
            assert nearest(turned(points[::2], symmetry["axis"], aside, 1.0), points).max() > tolerance


def test_lmo_is_image_3_of_scene_2_with_sam6d_depth(lmo):
    scene, source = lmo / "test" / "000002", LMO / "data" / "bop" / "lmo"
    assert os.listdir(lmo / "test") == ["000002"]
    assert os.listdir(scene / "rgb") == os.listdir(scene / "depth") == ["000003.png"]
    assert (scene / "depth" / "000003.png").read_bytes() == \
        (LMO / "SAM-6D" / "Data" / "Example" / "depth.png").read_bytes()
    assert (scene / "rgb" / "000003.png").read_bytes() == \
        (source / "test" / "000002" / "rgb" / "000003.png").read_bytes()
    for name in ("scene_camera", "scene_gt", "scene_gt_info"):
        assert load(scene / f"{name}.json") == {"3": load(source / "test" / "000002" / f"{name}.json")["3"]}
    assert load(lmo / "camera.json")["depth_scale"] == 1.0
    targets = load(lmo / "test_targets_bop19.json")
    assert targets == [{"im_id": 3, "inst_count": 1, "obj_id": obj_id, "scene_id": 2}
                       for obj_id in (1, 5, 6, 8, 9, 10, 11, 12)]
    assert sorted(os.listdir(lmo / "models")) == sorted(os.listdir(source / "models"))
    assert load(lmo / "models" / "models_info.json") == load(source / "models" / "models_info.json")


def test_bad_usage_exits_2(tmp_path):
    for args in [(), ("ycbv",), ("coco", tmp_path / "out"), ("lmo", tmp_path / "out", "extra"), ("lmo", "--nope")]:
        done = run(*args)
        assert done.returncode == 2, args
        assert "usage" in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists()


def test_a_non_empty_out_dir_is_replaced_only_with_force(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    refused = run("lmo", out)
    assert refused.returncode == 1 and str(out) in refused.stderr and "--force" in refused.stderr
    assert os.listdir(out) == ["keep.txt"] and (out / "keep.txt").read_text() == "mine"
    assert os.listdir(tmp_path) == ["out"]
    replaced = run("lmo", out, "--force")
    assert replaced.returncode == 0, replaced.stderr
    assert sorted(os.listdir(out)) == ["camera.json", "models", "test", "test_targets_bop19.json"]
    assert os.listdir(tmp_path) == ["out"]


def test_a_failing_run_leaves_no_dataset(tmp_path):
    # The scenes are there, the models are not: the run fails after writing the images.
    data = tmp_path / "data"
    (data / "ycbv_subset").mkdir(parents=True)
    for part in ("Example-Scenes", "derived"):
        (data / "ycbv_subset" / part).symlink_to(YCBV / part)
    failed = run("ycbv", tmp_path / "out", data_dir=data)
    assert failed.returncode == 1
    assert str(data / "ycbv_subset" / "models") in failed.stderr and "Traceback" not in failed.stderr
    assert sorted(os.listdir(tmp_path)) == ["data"]
