"""open_camera: an .oni recording of real frames (written by `ecvpose record`) yields the frames as load_frame reads
them, so a recognizer finds the same objects; no device is a clear InputError, at once."""

import os
import subprocess
import time

import numpy as np
import pytest

import ecvpose
from conftest import DATA_DIR

VIDEO = DATA_DIR / "ycbv_subset" / "Example-Scenes" / "0001"
FRAMES = [str(VIDEO / name) for name in ("000001", "000003", "000005")]


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """The first three frames of YCB-Video video 0001 as FILE.oni (and FILE.oni.json), through the CLI."""
    folder = tmp_path_factory.mktemp("recording")
    frames = folder / "frames.txt"
    frames.write_text("\n".join(FRAMES) + "\n")
    path = folder / "video.oni"
    subprocess.run([os.environ["ECVPOSE_CLI"], "record", "--sequence", str(frames), "--out", str(path)],
                   check=True, capture_output=True)
    return str(path)


def test_recording_yields_the_source_frames(recording):
    camera = ecvpose.open_camera(recording)
    assert camera.num_frames == 3
    assert camera.intrinsics_source == recording + ".json"
    frames = list(camera)
    assert len(frames) == 3
    for frame, spec in zip(frames, FRAMES):
        expected = ecvpose.load_frame(spec)
        np.testing.assert_array_equal(frame.color, expected.color)
        np.testing.assert_array_equal(frame.depth, expected.depth)  # metres, the same floats
        np.testing.assert_array_equal(frame.K, expected.K)


def test_recording_recognises_as_the_frame_files(recording, demo_library):
    recognizer = ecvpose.Recognizer(demo_library)
    found = 0
    for frame, spec in zip(ecvpose.open_camera(recording), FRAMES):
        got = recognizer.recognize_frame(frame)
        expected = recognizer.recognize_frame(ecvpose.load_frame(spec))
        assert [d.model for d in got] == [d.model for d in expected]
        assert [d.score for d in got] == [d.score for d in expected]
        for a, b in zip(got, expected):
            np.testing.assert_array_equal(a.camera_from_object, b.camera_from_object)
        found += len(got)
    assert found >= 3


def test_given_k_overrides_the_calibration_file(recording):
    k = np.array([[500.0, 0, 320], [0, 501.0, 240], [0, 0, 1]])
    camera = ecvpose.open_camera(recording, K=k)
    assert camera.intrinsics_source == "given"
    np.testing.assert_array_equal(next(iter(camera)).K, k)


def test_no_device_is_an_input_error_at_once():
    start = time.monotonic()
    with pytest.raises(ecvpose.InputError, match="openni2://: device"):
        ecvpose.open_camera("openni2://")
    assert time.monotonic() - start < 5.0
    with pytest.raises(ecvpose.InputError, match="recording"):
        ecvpose.open_camera("/nonexistent/video.oni")
