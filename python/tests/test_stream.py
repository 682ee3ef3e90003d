"""A stream from Python: the frames of a video followed as `ecvpose recognize --sequence --track` follows them."""

import json
import os
import subprocess
import time

import numpy as np

import ecvpose
from conftest import DATA_DIR

VIDEO = str(DATA_DIR / "ycbv_subset" / "Example-Scenes" / "0001")


def test_tracking_a_video_gives_the_command_lines_detections(demo_library, demo_library_path, tmp_path):
    frames = ecvpose.list_frames(VIDEO)
    assert len(frames) == 10 and frames == sorted(frames)
    recognizer = ecvpose.Recognizer(demo_library, track=True, search_every=3, seed=2)
    from_python = [recognizer.recognize_frame(ecvpose.load_frame(spec)) for spec in frames]
    assert any(d.tracked for detections in from_python for d in detections)

    out = tmp_path / "sequence.jsonl"
    run = subprocess.run([os.environ["ECVPOSE_CLI"], "recognize", "--db", str(demo_library_path), "--sequence", VIDEO,
                          "--track", "--search-every", "3", "--seed", "2", "--threads", "2", "--out-json", str(out)],
                         capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert [line["frame"] for line in lines] == frames
    for detections, line in zip(from_python, lines):
        assert [(d.model, d.tracked) for d in detections] == [(d["model"], d["tracked"]) for d in line["detections"]]
        for detection, written in zip(detections, line["detections"]):
            assert abs(detection.score - written["score"]) < 1e-6
            np.testing.assert_allclose(detection.camera_from_object, written["camera_from_object"], atol=1e-6)


def test_draw_marks_the_detections_and_write_image_writes_them(demo_library, demo_frame, tmp_path):
    recognizer = ecvpose.Recognizer(demo_library)
    detections = recognizer.recognize_frame(demo_frame)
    picture = recognizer.draw(demo_frame.color, demo_frame.depth, demo_frame.K, detections)
    assert picture.shape == demo_frame.color.shape and picture.dtype == np.uint8
    changed = np.any(picture != demo_frame.color, axis=2)
    assert changed.mean() > 0.05  # three objects in red, over a twentieth of the image
    untouched = recognizer.draw(demo_frame.color, demo_frame.depth, demo_frame.K, [])
    np.testing.assert_array_equal(untouched, demo_frame.color)
    path = tmp_path / "overlay.png"
    ecvpose.write_image(str(path), picture)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_search_beside_the_tracking_brings_its_objects_into_a_later_call(demo_library, demo_frame):
    recognizer = ecvpose.Recognizer(demo_library, track=True, search_beside=True, threads=2)
    assert recognizer.recognize_frame(demo_frame) == []  # follows nothing yet; the searcher takes this frame
    assert recognizer.last_searched_frames_ago is None
    calls, deadline = 1, time.monotonic() + 120.0
    while recognizer.last_searched_frames_ago is None and time.monotonic() < deadline:
        time.sleep(0.03)  # a camera's interval
        detections = recognizer.recognize_frame(demo_frame)
        calls += 1
    assert recognizer.last_searched_frames_ago == calls - 1  # the first call's frame was searched
    names = {model.name for model in demo_library.models}
    truth = {model: pose for model, pose in demo_frame.ground_truth if model in names}
    assert sorted(d.model for d in detections) == sorted(truth)
    for detection in detections:
        error_m = np.linalg.norm(detection.camera_from_object[:3, 3] - truth[detection.model][:3, 3])
        assert error_m < 0.01, (detection.model, error_m)
