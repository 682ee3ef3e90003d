"""ecvpose: known objects and their 6D pose in RGB-D images.

Build a model library from textured meshes, then find its models in RGB-D frames held as numpy arrays::

    import ecvpose
    ecvpose.build_models("lib.sqlite", "models/meshes")
    library = ecvpose.ModelLibrary.open("lib.sqlite")
    recognizer = ecvpose.Recognizer(library, track=True)
    for detection in recognizer.recognize(color, depth, K):
        print(detection.model, detection.score, detection.camera_from_object)

Colour images are RGB (HxWx3 uint8), depth images metres (HxW float32) or sensor units (uint16, with depth_scale),
poses 4x4 float64 arrays in metres. Bad input raises InputError (a ValueError) naming the argument or file.
"""

from ._ecvpose import (  # noqa: F401
    Camera,
    Detection,
    Frame,
    InputError,
    Model,
    ModelLibrary,
    Recognizer,
    RenderError,
    __version__,
    build_models,
    list_frames,
    load_frame,
    merge_libraries,
    open_camera,
    render,
    write_image,
)

__all__ = [
    "Camera",
    "Detection",
    "Frame",
    "InputError",
    "Model",
    "ModelLibrary",
    "Recognizer",
    "RenderError",
    "__version__",
    "build_models",
    "list_frames",
    "load_frame",
    "merge_libraries",
    "open_camera",
    "render",
    "write_image",
]
