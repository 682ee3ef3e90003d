"""Recognition from Python: the demo frame's objects at their true poses, from arrays and from files alike."""

import math

import numpy as np
import pytest

import ecvpose

# Translation and rotation errors allowed against the ground truth: the C++ end-to-end test finds the boxes within
# 2 mm / 2 degrees; the mustard bottle's turn about its own axis is weakly held (4-6 degrees off over seeds).
MAX_TRANSLATION_M = 0.015
MAX_ROTATION_DEG = 10.0


def rotation_deg(a, b):
    cosine = (np.trace(a[:3, :3].T @ b[:3, :3]) - 1.0) / 2.0
    return math.degrees(math.acos(max(-1.0, min(1.0, cosine))))


def test_finds_the_three_objects_of_the_demo_frame_at_their_true_poses(demo_library, demo_frame):
    recognizer = ecvpose.Recognizer(demo_library, threads=2, seed=1)
    detections = recognizer.recognize(demo_frame.color, demo_frame.depth, demo_frame.K)
    names = {model.name for model in demo_library.models}
    truth = {model: pose for model, pose in demo_frame.ground_truth if model in names}
    assert len(truth) == 3
    assert sorted(d.model for d in detections) == sorted(truth)  # all three, nothing else
    for detection in detections:
        pose = detection.camera_from_object
        assert pose.shape == (4, 4) and pose.dtype == np.float64
        assert 0.3 <= detection.score <= 1.0
        assert detection.hypothesis in ("context", "ppf")
        assert not detection.tracked
        error_m = np.linalg.norm(pose[:3, 3] - truth[detection.model][:3, 3])
        assert error_m < MAX_TRANSLATION_M, (detection.model, error_m)
        assert rotation_deg(pose, truth[detection.model]) < MAX_ROTATION_DEG, detection.model
        # At a right pose the frame explains most of the surface and is not seen through it.
        assert detection.explained_surface > 0.4, (detection.model, detection.explained_surface)
        assert detection.free_space_violation < 0.1, (detection.model, detection.free_space_violation)
        assert 0.0 <= detection.occluding_contour + detection.creased_contour <= 1.0
    timings = recognizer.last_timings_ms
    assert timings["total"] > 0.0 and "verify" in timings


def same_detections(a, b):
    assert [d.model for d in a] == [d.model for d in b]
    for x, y in zip(a, b):
        assert x.score == y.score
        np.testing.assert_allclose(x.camera_from_object, y.camera_from_object, rtol=0, atol=1e-9)


def test_arrays_files_and_other_layouts_give_the_same_detections(demo_library, demo_frame):
    def run(*args, **kwargs):
        return ecvpose.Recognizer(demo_library, seed=3).recognize(*args, **kwargs)

    from_arrays = run(demo_frame.color, demo_frame.depth, demo_frame.K)
    assert len(from_arrays) >= 2
    same_detections(from_arrays, ecvpose.Recognizer(demo_library, seed=3).recognize_frame(demo_frame))
    # Depth in sensor units (YCB-Video's PNG holds 10 000 per metre), K as nested lists.
    depth_units = np.round(demo_frame.depth * 10000.0).astype(np.uint16)
    same_detections(from_arrays, run(demo_frame.color, depth_units, demo_frame.K.tolist(), depth_scale=10000))
    # Colour as a view with negative strides and depth inside a wider array: copied, not refused.
    bgr = np.ascontiguousarray(demo_frame.color[:, :, ::-1])
    wide = np.zeros((480, 700), np.float32)
    wide[:, :640] = demo_frame.depth
    same_detections(from_arrays, run(bgr[:, :, ::-1], wide[:, :640], demo_frame.K))


def test_the_callers_arrays_are_left_alone(demo_library, demo_frame):
    color, depth = demo_frame.color.copy(), demo_frame.depth.copy()
    ecvpose.Recognizer(demo_library).recognize(color, depth, demo_frame.K)
    np.testing.assert_array_equal(color, demo_frame.color)
    np.testing.assert_array_equal(depth, demo_frame.depth)


def test_tracking_follows_objects_from_call_to_call_until_reset(demo_library, demo_frame):
    recognizer = ecvpose.Recognizer(demo_library, track=True)
    first = recognizer.recognize_frame(demo_frame)
    assert first and not any(d.tracked for d in first)
    second = recognizer.recognize_frame(demo_frame)
    assert sorted(d.model for d in second) == sorted(d.model for d in first)
    # followed, or confirmed by the search its new track was due for (that pose scored higher on the same surface)
    assert all(d.tracked or d.confirmed for d in second)
    recognizer.reset()
    assert not any(d.tracked for d in recognizer.recognize_frame(demo_frame))


def test_render_draws_a_model_where_its_pose_puts_it(demo_library, demo_frame):
    model, pose = next(truth for truth in demo_frame.ground_truth if truth[0] == "004_sugar_box")
    color, depth = ecvpose.render(demo_library, model, pose, demo_frame.K, 640, 480)
    assert color.shape == (480, 640, 3) and color.dtype == np.uint8
    assert depth.shape == (480, 640) and depth.dtype == np.float32
    seen = depth > 0
    assert seen.sum() > 1000
    # The centre of the rendered pixels lies near the projection of the object's origin, the depths around its z.
    u, v, w = demo_frame.K @ pose[:3, 3]
    rows, cols = np.nonzero(seen)
    assert abs(cols.mean() - u / w) < 40 and abs(rows.mean() - v / w) < 40
    diameter = next(m.diameter_m for m in demo_library.models if m.name == model)
    assert abs(float(np.median(depth[seen])) - pose[2, 3]) < diameter / 2
    assert color[seen].mean() > 20  # the model's colours, not the black background
