"""BOP's localisation task through the command line: `ecvpose bop` over a BOP-layout dataset made from the YCB-Video
frames (scripts/make_bop_dataset), resumed after an interruption; `recognize --targets`; and the continuous symmetry
that models_info.json gives the master chef can taking MSSD to 0 in `eval --metric bop`."""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import DATA_DIR, DEMO_FRAME, SOURCE_DIR

CLI = os.environ.get("ECVPOSE_CLI", str(SOURCE_DIR / "build" / "app" / "ecvpose"))
# Video 0001 is scene 1: 002_master_chef_can (1, not in the demo library), 003_cracker_box (2), 004_sugar_box (3),
# 006_mustard_bottle (5) in each image.
IMAGES = [(1, 1), (1, 3)]
DEMO_OBJECTS = {2: "003_cracker_box", 3: "004_sugar_box", 5: "006_mustard_bottle"}


def run(*args):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, timeout=300)


def load(path):
    with open(path) as file:
        return json.load(file)


def rows(path):
    """The CSV's rows (header checked) as lists of cells."""
    with open(path) as file:
        lines = file.read().splitlines()
    assert lines[0] == "scene_id,im_id,obj_id,score,R,t,time"
    return [line.split(",") for line in lines[1:] if line]


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("bop") / "ycbv"
    made = subprocess.run([sys.executable, str(SOURCE_DIR / "scripts" / "make_bop_dataset"), "ycbv", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert made.returncode == 0, made.stderr
    targets = [t for t in load(out / "test_targets_bop19.json") if (t["scene_id"], t["im_id"]) in IMAGES]
    assert len(targets) == 8
    with open(out / "two_images.json", "w") as file:
        json.dump(targets, file)
    return out


def test_bop_runs_every_target_image_resumes_and_reports_average_recall(dataset, demo_library_path, tmp_path):
    out, ar = tmp_path / "results.csv", tmp_path / "ar.json"
    command = ["bop", "--dataset", dataset, "--targets", dataset / "two_images.json", "--db", demo_library_path,
               "--out", out]
    first = run(*command, "--out-json", ar)
    assert first.returncode == 0, first.stderr
    assert "[2/2] scene 1 image 3" in first.stderr and "(and 1 without a model)" in first.stderr
    assert not (tmp_path / "results.csv.progress").exists()
    estimates = rows(out)
    assert {(int(r[0]), int(r[1])) for r in estimates} == set(IMAGES)
    assert {int(r[2]) for r in estimates} <= set(DEMO_OBJECTS)
    for image in IMAGES:  # at most one estimate per target object; one time per image, as BOP asks
        objects = [int(r[2]) for r in estimates if (int(r[0]), int(r[1])) == image]
        assert len(objects) == len(set(objects))
        assert len({r[6] for r in estimates if (int(r[0]), int(r[1])) == image}) == 1
    recall = load(ar)
    for name in DEMO_OBJECTS.values():
        assert recall["models"][name]["instances"] == 2
        assert recall["models"][name]["ar"] > 0.7, (name, recall)
    assert recall["models"]["obj_000001 (no model)"] == {"instances": 2, "ar": 0.0, "ar_vsd": 0.0, "ar_mssd": 0.0,
                                                         "ar_mspd": 0.0}
    assert recall["all"]["instances"] == 8
    assert "Over the objects the library has a model of (6 instances)" in first.stdout

    # Interrupted while writing the second image: its progress line missing, half a row in the CSV.
    with open(out) as file:
        complete = file.read()
    first_image = [line for line in complete.splitlines()[1:] if line.startswith("1,1,")]
    (tmp_path / "results.csv.progress").write_text("1 1\n")
    with open(out, "a") as file:
        file.write("1,3,2,0.5,1 0 0")
    resumed = run(*command)
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming" in resumed.stderr and "1 of 2 images done" in resumed.stderr
    assert "bop: [2/2] scene 1 image 3" in resumed.stderr and "bop: [1/2] scene" not in resumed.stderr
    again = rows(out)
    assert [",".join(r) for r in again if r[:2] == ["1", "1"]] == first_image
    second = {int(r[2]): r for r in estimates if r[:2] == ["1", "3"]}
    redone = {int(r[2]): r for r in again if r[:2] == ["1", "3"]}
    assert redone.keys() == second.keys()
    for obj, row in redone.items():  # the same poses again
        t_then, t_now = np.array(second[obj][5].split(), float), np.array(row[5].split(), float)
        assert np.linalg.norm(t_then - t_now) < 1.0, (obj, t_then, t_now)

    # A finished run is judged again, not run again.
    with open(out) as file:
        finished = file.read()
    judged = run(*command)
    assert judged.returncode == 0, judged.stderr
    assert "is a finished run" in judged.stderr and "[1/2] scene" not in judged.stderr
    with open(out) as file:
        assert file.read() == finished

    # Progress of another run's images is refused, naming the file.
    (tmp_path / "results.csv.progress").write_text("7 7\n")
    other = run(*command)
    assert other.returncode == 1
    assert "results.csv.progress:1" in other.stderr and "--restart" in other.stderr
    assert run(*command, "--restart").returncode == 0


def test_recognize_targets_reports_only_the_targets_of_the_frame(dataset, demo_library_path, tmp_path):
    targets = tmp_path / "targets.json"
    targets.write_text(json.dumps([{"scene_id": 1, "im_id": 1, "obj_id": 2, "inst_count": 1}]))
    found = run("recognize", "--db", demo_library_path, DEMO_FRAME, "--targets", targets, "--scene-id", 1,
                "--image-id", 1, "--out-json", tmp_path / "d.json", "--out-bop", tmp_path / "d.csv")
    assert found.returncode == 0, found.stderr
    assert [d["model"] for d in load(tmp_path / "d.json")["detections"]] == ["003_cracker_box"]
    assert [r[:3] for r in rows(tmp_path / "d.csv")] == [["1", "1", "2"]]
    elsewhere = run("recognize", "--db", demo_library_path, DEMO_FRAME, "--targets", targets, "--scene-id", 1,
                    "--image-id", 2)
    assert elsewhere.returncode == 1
    assert str(targets) in elsewhere.stderr and "scene 1 image 2" in elsewhere.stderr


def turned_about(axis, offset_m, angle):
    """4x4 turn by `angle` about the line through `offset_m` along `axis` (Rodrigues)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    skew = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    rotation = np.eye(3) + math.sin(angle) * skew + (1 - math.cos(angle)) * skew @ skew
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    matrix[:3, 3] = np.asarray(offset_m) - rotation @ np.asarray(offset_m)
    return matrix


def test_the_cans_listed_symmetry_takes_mssd_to_zero(dataset, tmp_path):
    library = tmp_path / "can.sqlite"
    mesh = DATA_DIR / "ycbv_subset" / "models" / "002_master_chef_can" / "textured_simple.obj"
    built = run("modeldb", "build", mesh, "--name", "002_master_chef_can", "--allow-missing-textures", "--views", 2,
                "--db", library)
    assert built.returncode == 0, built.stderr
    symmetry = load(dataset / "models" / "models_info.json")["1"]["symmetries_continuous"][0]
    truth = next(o for o in load(dataset / "test" / "000001" / "scene_gt.json")["1"] if o["obj_id"] == 1)
    camera_from_object = np.eye(4)
    camera_from_object[:3, :3] = np.reshape(truth["cam_R_m2c"], (3, 3))
    camera_from_object[:3, 3] = np.asarray(truth["cam_t_m2c"]) / 1000.0
    turned = camera_from_object @ turned_about(symmetry["axis"], np.asarray(symmetry["offset"]) / 1000.0, 3.0)
    detections = tmp_path / "turned.json"
    detections.write_text(json.dumps({"detections": [{"model": "002_master_chef_can", "score": 0.9,
                                                      "camera_from_object": turned.tolist()}]}))
    frame = f"{dataset}/test/000001:1"
    judged = {}
    for name, extra in (("symmetric", ["--models-info", dataset / "models" / "models_info.json"]), ("plain", [])):
        result = run("eval", "--db", library, "--detections", detections, frame, "--metric", "bop",
                     "--out-json", tmp_path / f"{name}.json", *extra)
        assert result.returncode == 0, result.stderr
        judged[name] = load(tmp_path / f"{name}.json")["models"]["002_master_chef_can"]
    assert judged["symmetric"]["ar_mssd"] == 1.0 and judged["symmetric"]["ar_mspd"] == 1.0
    assert judged["plain"]["ar_mssd"] == 0.0, judged["plain"]  # turned by 3 rad: 10 cm off without the symmetry


def test_python_recognize_targets_reports_a_rejected_best_pose(demo_library, demo_frame):
    import ecvpose

    found = ecvpose.Recognizer(demo_library).recognize_targets(demo_frame, {"004_sugar_box": 1})
    assert [(d.model, d.accepted) for d in found] == [("004_sugar_box", True)]
    strict = ecvpose.Recognizer(demo_library, min_score=0.999)
    assert strict.recognize_frame(demo_frame) == []
    rejected = strict.recognize_targets(demo_frame, {"004_sugar_box": 1})
    assert [(d.model, d.accepted) for d in rejected] == [("004_sugar_box", False)]
    assert np.linalg.norm(np.asarray(rejected[0].camera_from_object)[:3, 3]
                          - np.asarray(found[0].camera_from_object)[:3, 3]) < 0.01
