"""`ecvpose recognize --sequence` as a stream: lines written as frames are done, standard output, --follow."""

import json
import os
import subprocess
import time

import ecvpose
from conftest import DATA_DIR, DEMO_FRAME

VIDEO = str(DATA_DIR / "ycbv_subset" / "Example-Scenes" / "0001")


def recognize(library_path, *flags):
    return [os.environ["ECVPOSE_CLI"], "recognize", "--db", str(library_path), "--threads", "2", *flags]


def test_a_reader_sees_whole_lines_while_the_sequence_runs(demo_library_path, tmp_path):
    out = tmp_path / "sequence.jsonl"
    process = subprocess.Popen(recognize(demo_library_path, "--sequence", VIDEO, "--out-json", str(out)),
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    seen_while_running = set()
    while process.poll() is None:
        if out.exists():
            text = out.read_text()
            complete = text[: text.rfind("\n") + 1]
            lines = complete.splitlines()
            for line in lines:
                assert "detections" in json.loads(line)  # every finished line is a whole JSON object
            seen_while_running.add(len(lines))
        time.sleep(0.05)
    assert process.returncode == 0
    assert any(1 <= count < 10 for count in seen_while_running)  # lines were there before the end
    assert len(out.read_text().splitlines()) == 10


def test_detections_to_standard_output_and_the_report_to_standard_error(demo_library_path):
    run = subprocess.run(recognize(demo_library_path, DEMO_FRAME, "--out-json", "-"), capture_output=True, text=True,
                         check=False)
    assert run.returncode == 0, run.stderr
    assert len(json.loads(run.stdout)["detections"]) == 3
    assert "3 detections" in run.stderr
    run = subprocess.run(recognize(demo_library_path, "--sequence", VIDEO, "--out-bop", "-"),
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    rows = run.stdout.splitlines()
    assert rows[0] == "scene_id,im_id,obj_id,score,R,t,time"
    assert len(rows) >= 1 + 25 and all(row.startswith("1,") for row in rows[1:])  # scene 0001, 3 objects a frame
    assert "10 frames in" in run.stderr
    both = subprocess.run(recognize(demo_library_path, DEMO_FRAME, "--out-json", "-", "--out-bop", "-"),
                          capture_output=True, text=True, check=False)
    assert both.returncode == 2 and "standard output" in both.stderr


def write_frame_json(folder, name):
    """A frame JSON naming the demo frame's images, written by rename as a producer would."""
    frame = {"color": DEMO_FRAME + "-color.png", "depth": DEMO_FRAME + "-depth.png", "depth_scale": 10000,
             "camera": [1066.778, 1067.487, 312.9869, 241.3109]}
    temporary = folder / (name + ".tmp")
    temporary.write_text(json.dumps(frame))
    os.rename(temporary, folder / (name + ".json"))


def test_follow_takes_a_frame_written_after_it_started(demo_library_path, tmp_path):
    folder = tmp_path / "incoming"
    folder.mkdir()
    write_frame_json(folder, "000001")
    out = tmp_path / "followed.jsonl"
    process = subprocess.Popen(recognize(demo_library_path, "--sequence", str(folder), "--follow", "--track",
                                         "--idle-timeout", "3", "--out-json", str(out)),
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    while not (out.exists() and out.read_text().count("\n") == 1):
        assert time.time() < deadline and process.poll() is None
        time.sleep(0.05)
    write_frame_json(folder, "000002")
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 0, stderr
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert [os.path.basename(line["frame"]) for line in lines] == ["000001.json", "000002.json"]
    # followed, or confirmed by the search that its first track was due for (its pose scored higher on that surface)
    assert all(d["tracked"] or d["confirmed"] for d in lines[1]["detections"]) and len(lines[1]["detections"]) == 3


def test_bop_rows_of_frame_jsons_take_their_ids_or_count_from_0(demo_library_path, tmp_path):
    folder = tmp_path / "frames"
    folder.mkdir()
    write_frame_json(folder, "a")
    write_frame_json(folder, "b")
    named = json.loads((folder / "b.json").read_text())
    (folder / "b.json").write_text(json.dumps(dict(named, scene_id=5, image_id=42)))
    out = tmp_path / "rows.csv"
    run = subprocess.run(recognize(demo_library_path, "--sequence", str(folder), "--out-bop", str(out)),
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    rows = [row.split(",") for row in out.read_text().splitlines()[1:]]
    assert sorted((row[0], row[1], row[2]) for row in rows) == sorted(
        [("0", "0", obj) for obj in ("2", "3", "5")] + [("5", "42", obj) for obj in ("2", "3", "5")])  # YCB indices


def test_modeldb_list_shows_each_models_bop_obj_id(tmp_path):
    db = str(tmp_path / "named.sqlite")
    sugar = os.path.join(os.path.dirname(DEMO_FRAME), "..", "meshes", "004_sugar_box", "004_sugar_box.obj")
    ecvpose.build_models(db, sugar, name="sugar", views=4)
    ecvpose.build_models(db, sugar, views=4)
    ecvpose.build_models(db, sugar, name="sugar", views=4)  # built again: the same number
    listed = subprocess.run([os.environ["ECVPOSE_CLI"], "modeldb", "list", "--db", db, "--json"], capture_output=True,
                            text=True, check=True)
    models = {model["name"]: model for model in json.loads(listed.stdout)}
    assert models["sugar"]["bop_obj_id"] == models["sugar"]["id"] == 1
    assert models["004_sugar_box"]["bop_obj_id"] == 3 and models["004_sugar_box"]["id"] == 2
    table = subprocess.run([os.environ["ECVPOSE_CLI"], "modeldb", "list", "--db", db], capture_output=True, text=True,
                           check=True).stdout
    assert "obj_id" in table.splitlines()[1]
