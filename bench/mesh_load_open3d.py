#!/usr/bin/env python3
"""Open3D reading textured meshes: the peer of setup_bench's mesh loading (issue 9, "Benchmarks").

Called by setup_bench in the same run; not a test. Needs Open3D for the interpreter it runs under:
    apt-get install -y python3-open3d      (Debian 12: Open3D 0.16 for /usr/bin/python3)

    mesh_load_open3d.py MESH [MESH ...]

Reads each mesh with open3d.io.read_triangle_mesh (OBJ + MTL + texture images, no post-processing) and prints
one line: "total_ms triangles textures", the wall time of all reads, and the triangles and decoded texture
pixels (megapixels) read. Open3D 0.16 takes a texture name with the trailing space YCB's MTL files have
("map_Kd x.png ") for part of the name, and reads no texture; so each OBJ is read from a scratch folder of
links to it and its images, beside a copy of its MTL with the names trimmed (not timed).
Exit code 3 when Open3D cannot be imported, 1 when a mesh or one of its textures does not load.
"""

import os
import sys
import tempfile
import time


def trimmed_copy(obj_path, folder):
    """Links to the OBJ and the files beside it in `folder`, with MTLs rewritten without trailing spaces."""
    source = os.path.dirname(os.path.abspath(obj_path))
    for name in os.listdir(source):
        target = os.path.join(folder, name)
        if name.endswith(".mtl"):
            with open(os.path.join(source, name)) as mtl, open(target, "w") as out:
                out.writelines(line.rstrip() + "\n" for line in mtl)
        else:
            os.symlink(os.path.join(source, name), target)
    return os.path.join(folder, os.path.basename(obj_path))


def main():
    try:
        import numpy as np
        import open3d as o3d
    except ImportError:
        sys.exit(3)
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    with tempfile.TemporaryDirectory() as scratch:
        paths = []
        for i, path in enumerate(sys.argv[1:]):
            folder = os.path.join(scratch, str(i))
            os.mkdir(folder)
            paths.append(trimmed_copy(path, folder) if path.endswith(".obj") else path)
        start = time.perf_counter()
        meshes = [o3d.io.read_triangle_mesh(path, enable_post_processing=False) for path in paths]
        total_ms = (time.perf_counter() - start) * 1000.0
        triangles = megapixels = 0.0
        for path, mesh in zip(sys.argv[1:], meshes):
            images = [np.asarray(texture) for texture in mesh.textures if not texture.is_empty()]
            pixels = sum(image.shape[0] * image.shape[1] for image in images)
            if len(mesh.triangles) == 0 or (path.endswith(".obj") and pixels == 0):
                print(f"{path}: {len(mesh.triangles)} triangles, {pixels} texture pixels", file=sys.stderr)
                sys.exit(1)
            triangles += len(mesh.triangles)
            megapixels += pixels / 1e6
    print(f"{total_ms:.1f} {triangles:.0f} {megapixels:.1f}")


if __name__ == "__main__":
    main()
