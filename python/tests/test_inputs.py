"""Bad arguments raise ecvpose.InputError (a ValueError) whose message names the argument or file."""

import numpy as np
import pytest

import ecvpose
from conftest import DEMO_FRAME


@pytest.fixture(scope="module")
def recognizer(demo_library):
    return ecvpose.Recognizer(demo_library)


def raises_naming(name, call, *args, **kwargs):
    with pytest.raises(ecvpose.InputError) as error:
        call(*args, **kwargs)
    assert name in str(error.value), str(error.value)
    return str(error.value)


def test_input_error_is_a_value_error():
    assert issubclass(ecvpose.InputError, ValueError)


def test_arrays_of_the_wrong_type_shape_or_size_are_named(recognizer, demo_frame):
    color, depth, k = demo_frame.color, demo_frame.depth, demo_frame.K
    message = raises_naming("color", recognizer.recognize, color.astype(np.float64), depth, k)
    assert "uint8" in message and "float64" in message
    raises_naming("color", recognizer.recognize, color[:, :, 0], depth, k)
    raises_naming("depth", recognizer.recognize, color, depth.astype(np.float64), k)
    raises_naming("depth", recognizer.recognize, color, depth[::2, ::2], k)
    raises_naming("depth_scale", recognizer.recognize, color, (depth * 1000).astype(np.uint16), k)
    raises_naming("depth_scale", recognizer.recognize, color, (depth * 1000).astype(np.uint16), k, depth_scale=-1)
    raises_naming("depth_scale", recognizer.recognize, color, depth, k, depth_scale=1000)
    broken = depth.copy()
    broken[10, 20] = np.nan
    assert "pixel (20, 10)" in raises_naming("depth", recognizer.recognize, color, broken, k)


def test_a_bad_camera_matrix_is_named(recognizer, demo_frame):
    color, depth = demo_frame.color, demo_frame.depth
    k = demo_frame.K.copy()
    k[0, 0] = np.nan
    raises_naming("K", recognizer.recognize, color, depth, k)
    raises_naming("K", recognizer.recognize, color, depth, np.eye(2))
    raises_naming("K", recognizer.recognize, color, depth, "not a matrix")
    skewed = demo_frame.K.copy()
    skewed[0, 1] = 0.5
    raises_naming("K", recognizer.recognize, color, depth, skewed)
    negative = demo_frame.K.copy()
    negative[1, 1] = -1.0
    raises_naming("K", recognizer.recognize, color, depth, negative)


def test_thread_counts_are_bounded(demo_library):
    for threads in (0, 257, 10**6):
        message = raises_naming("threads", ecvpose.Recognizer, demo_library, threads=threads)
        assert "1 to 256" in message, message
    assert ecvpose.Recognizer(demo_library, threads=256) is not None


def test_bad_options_files_and_names_are_named(demo_library, demo_library_path, tmp_path, demo_frame):
    raises_naming("threads", ecvpose.Recognizer, demo_library, threads=0)
    raises_naming("track_score", ecvpose.Recognizer, demo_library, track=True, track_score=1.5)
    raises_naming("hypotheses", ecvpose.Recognizer, demo_library, hypotheses="colour")
    raises_naming("search_every", ecvpose.Recognizer, demo_library, search_every=3)  # without track
    raises_naming("matcher", ecvpose.Recognizer, demo_library, matcher="brute")
    raises_naming("colour_weight", ecvpose.Recognizer, demo_library, colour_weight=1.0)  # not a recognize flag
    raises_naming("track", ecvpose.Recognizer, demo_library, track="yes")
    raises_naming("views_per_model", ecvpose.Recognizer, demo_library, views_per_model=2.5)
    missing = str(tmp_path / "missing.sqlite")
    raises_naming(missing, ecvpose.ModelLibrary.open, missing)
    not_a_library = tmp_path / "text.sqlite"
    not_a_library.write_text("hello")
    raises_naming(str(not_a_library), ecvpose.ModelLibrary.open, str(not_a_library))
    raises_naming(DEMO_FRAME + "9", ecvpose.load_frame, DEMO_FRAME + "9")
    raises_naming("load_frame", ecvpose.load_frame)
    raises_naming("banana", ecvpose.render, demo_library, "banana", np.eye(4), demo_frame.K, 640, 480)
    not_rigid = np.eye(4)
    not_rigid[0, 0] = 2.0
    raises_naming("camera_from_object", ecvpose.render, demo_library, "004_sugar_box", not_rigid, demo_frame.K, 64, 48)
    assert len(ecvpose.ModelLibrary.open(str(demo_library_path), models=["004_sugar_box"]).models) == 1
