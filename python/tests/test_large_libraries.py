"""A library built in parts (a Dask local cluster, the Slurm script's steps) and merged equals one build of the same
meshes; a finished library shared by several readers gets no files beside it."""

import json
import os
import shutil
import subprocess
import sys

import pytest

from conftest import DATA_DIR, DEMO_FRAME, DEMO_MESHES, SOURCE_DIR

CLI = os.environ.get("ECVPOSE_CLI", "ecvpose")
# Three textured YCB objects beside the demo's three meshes: six models, three parts.
YCB_OBJECTS = ["011_banana", "024_bowl", "077_rubiks_cube"]
QUICK = ["--views", "4"]


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    """One folder of six model folders (links), so that one build stores them in name order."""
    folder = tmp_path_factory.mktemp("meshes")
    for name in sorted(os.listdir(DEMO_MESHES)):
        if os.path.isdir(os.path.join(DEMO_MESHES, name)):
            os.symlink(os.path.join(DEMO_MESHES, name), folder / name)
    for name in YCB_OBJECTS:
        os.symlink(DATA_DIR / "ycb_objects" / name, folder / name)
    return folder


def models(library):
    """`modeldb list --json` without the time each model was stored."""
    listed = subprocess.run([CLI, "modeldb", "list", "--db", str(library), "--json"], capture_output=True, text=True,
                            check=True)
    return [{key: value for key, value in model.items() if key != "created"} for model in json.loads(listed.stdout)]


@pytest.fixture(scope="module")
def one_build(meshes, tmp_path_factory):
    library = tmp_path_factory.mktemp("one") / "one.sqlite"
    subprocess.run([CLI, "modeldb", "build", str(meshes), "--db", str(library), "--threads", "2", *QUICK],
                   check=True, capture_output=True)
    built = models(library)
    assert len(built) == 6
    return built


def assert_same_library(library, expected):
    merged = models(library)
    assert [m["name"] for m in merged] == [m["name"] for m in expected]
    for got, want in zip(merged, expected):
        assert got == want, got["name"]  # ids, digests of mesh and descriptors, counts, point pairs, settings
    verify = subprocess.run([CLI, "modeldb", "verify", "--db", str(library)], capture_output=True, text=True)
    assert verify.returncode == 0, verify.stdout
    assert not [p for p in os.listdir(library.parent) if p.endswith(("-wal", "-shm", "-journal"))]


def test_three_parts_on_a_dask_local_cluster_merge_into_the_one_build(meshes, one_build, tmp_path):
    pytest.importorskip("distributed", reason="python3-distributed (scripts/setup installs it)")
    library = tmp_path / "dask.sqlite"
    run = subprocess.run([sys.executable, "-m", "ecvpose.build_distributed", str(meshes), str(library), "--workers",
                          "2", "--parts", "3", *QUICK], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "merged 6 models of 3 parts" in run.stdout
    assert run.stderr.count("build_distributed: [") == 3  # a progress line per part
    assert_same_library(library, one_build)


def test_the_slurm_script_steps_build_the_parts_then_merge_into_the_one_build(meshes, one_build, tmp_path):
    script = str(SOURCE_DIR / "scripts" / "slurm" / "build_library.sbatch")
    library = tmp_path / "slurm.sqlite"
    environment = dict(os.environ, ECVPOSE=CLI, SLURM_ARRAY_TASK_COUNT="3", SLURM_CPUS_PER_TASK="2")
    for task in range(3):
        environment["SLURM_ARRAY_TASK_ID"] = str(task)
        run = subprocess.run(["bash", script, str(meshes), str(library), *QUICK], env=environment,
                             capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        assert f"(shard {task}/3)" in run.stdout
    del environment["SLURM_ARRAY_TASK_ID"]
    merge = subprocess.run(["bash", script, "--merge", str(meshes), str(library)], env=environment,
                           capture_output=True, text=True)
    assert merge.returncode == 0, merge.stderr
    assert "merged 6 models of 3 libraries" in merge.stdout
    assert_same_library(library, one_build)


def test_a_failed_part_names_its_mesh_and_the_other_parts_are_merged(meshes, tmp_path):
    pytest.importorskip("distributed", reason="python3-distributed (scripts/setup installs it)")
    broken = tmp_path / "meshes"
    shutil.copytree(meshes, broken, symlinks=True)
    (broken / "zz_broken").mkdir()
    (broken / "zz_broken" / "zz_broken.obj").write_text("v 0 0 0\nf 1 2 3\n")  # a face of missing vertices
    library = tmp_path / "partial.sqlite"
    run = subprocess.run([sys.executable, "-m", "ecvpose.build_distributed", str(broken), str(library), "--workers",
                          "2", "--parts", "3", *QUICK], capture_output=True, text=True, timeout=300)
    assert run.returncode == 1
    assert "FAILED" in run.stderr and "zz_broken" in run.stderr
    assert "merged 6 models of 3 parts" in run.stdout


def test_two_recognize_processes_and_a_service_leave_no_files_beside_the_library(demo_library_path, tmp_path):
    library = tmp_path / "shared.sqlite"
    shutil.copyfile(demo_library_path, library)
    recognize = [CLI, "recognize", "--db", str(library), "--threads", "1", DEMO_FRAME, "--out-json"]
    outputs = [tmp_path / "a.json", tmp_path / "b.json"]
    runs = [subprocess.Popen(recognize + [str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            for out in outputs]
    service = subprocess.run([CLI, "serve", "--db", str(library), "--threads", "1", "--root", os.path.dirname(DEMO_FRAME)],
                             input=json.dumps({"frame": DEMO_FRAME, "id": 1}) + "\n", capture_output=True, text=True,
                             timeout=120)
    assert service.returncode == 0, service.stderr
    answer = service.stdout
    for run in runs:
        assert run.wait(timeout=120) == 0, run.stderr.read()
    found = [sorted(d["model"] for d in json.loads(out.read_text())["detections"]) for out in outputs]
    served = sorted(d["model"] for d in json.loads(answer)["detections"])
    assert found[0] == found[1] == served == ["003_cracker_box", "004_sugar_box", "006_mustard_bottle"]
    assert sorted(os.listdir(tmp_path)) == ["a.json", "b.json", "shared.sqlite"]
