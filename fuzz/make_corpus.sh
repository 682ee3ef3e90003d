#!/usr/bin/env bash
# Seed corpora of the fuzz targets, made from the real files of the shared data: copied, or trimmed to a few KB (JSON
# to one image, meshes to their first faces, images and clouds to a crop through ecv_fuzz_seeds); the request lines
# of `ecvpose serve` from fuzz/corpus/serve_request (good and hostile ones, kept in the repository). Usage:
#   fuzz/make_corpus.sh DATA_DIR BUILD_DIR    # writes BUILD_DIR/corpus/<target>/seed-*; inputs fuzzing added stay
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: fuzz/make_corpus.sh DATA_DIR BUILD_DIR" >&2; exit 2; }
data=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
corpus=$build/corpus
work=$build/corpus-work
seeds() { ASAN_OPTIONS=detect_leaks=0 "$build/fuzz/ecv_fuzz_seeds" "$@"; }
separator=$'\n--ecvfuzz-part--\n'  # fuzz_util.h's kPartSeparator
rm -rf "$work"
mkdir -p "$work"
for target in png_frame frame_json ycbv_meta bop_scene bop_task pcd pose_json mesh_blob mesh serve_request oni; do
  mkdir -p "$corpus/fuzz_$target"
done

# The first K faces of an OBJ with the v, vt and vn lines they use, renumbered; other lines (mtllib, usemtl) first.
trim_obj() {
  awk -v K="$1" '
    function renumber(old, lines, map, kind,    n) {
      if (old == "") return ""
      if (!(old in map)) { n = ++count[kind]; map[old] = n; out[kind, n] = lines[old] }
      return map[old]
    }
    /^v /  { v[++nv] = $0; next }
    /^vt / { vt[++nvt] = $0; next }
    /^vn / { vn[++nvn] = $0; next }
    /^f /  { if (nf < K) face[++nf] = $0; next }
    { print }
    END {
      for (f = 1; f <= nf; ++f) {
        n = split(face[f], corner, " ")
        line = "f"
        for (i = 2; i <= n; ++i) {
          split(corner[i], index_, "/")
          a = renumber(index_[1], v, vmap, "v"); b = renumber(index_[2], vt, tmap, "vt")
          c = renumber(index_[3], vn, nmap, "vn")
          line = line " " a (corner[i] ~ /\// ? "/" b : "") (c != "" ? "/" c : "")
        }
        faces[f] = line
      }
      for (kind_i = 1; kind_i <= 3; ++kind_i) {
        kind = kind_i == 1 ? "v" : kind_i == 2 ? "vt" : "vn"
        for (i = 1; i <= count[kind]; ++i) print out[kind, i]
      }
      for (f = 1; f <= nf; ++f) print faces[f]
    }' "$2"
}

# The first K faces of an ASCII PLY with the vertices they use, renumbered, and the header's counts to match.
trim_ply() {
  awk -v K="$1" '
    in_header { header[++nh] = $0
                if ($1 == "element" && $2 == "vertex") { vertex_line = nh; vertices = $3 }
                if ($1 == "element" && $2 == "face") face_line = nh
                if ($1 == "end_header") in_header = 0
                next }
    read < vertices { vertex[read++] = $0; next }
    nf < K { line = $1
             for (i = 2; i <= $1 + 1; ++i) {
               if (!($i in map)) { map[$i] = used + 0; kept[used++] = vertex[$i] }
               line = line " " map[$i]
             }
             face[++nf] = line }
    END {
      for (i = 1; i <= nh; ++i) {
        if (i == vertex_line) print "element vertex " used
        else if (i == face_line) print "element face " nf
        else print header[i]
      }
      for (i = 0; i < used; ++i) print kept[i]
      for (f = 1; f <= nf; ++f) print face[f]
    }' in_header=1 "$2"
}

# PNG pair: the centre of a YCB-Video frame and of the LM-O frame.
ycbv=$data/ycbv_subset/Example-Scenes
seeds png-pair "$ycbv/0000/000001-color.png" "$ycbv/0000/000001-depth.png" "$corpus/fuzz_png_frame/seed-ycbv"
seeds png-pair "$data/lmo_subset/data/bop/lmo/test/000002/rgb/000003.png" \
  "$data/lmo_subset/SAM-6D/Data/Example/depth.png" "$corpus/fuzz_png_frame/seed-lmo"

# Frame JSON: YCB-Video's intrinsics and depth scale, naming fuzz_frame_json's good PNGs.
read -r fx fy cx cy _ _ scale < <(grep -v '^#' "$data/ycbv_subset/derived/intrinsics.txt")
printf '{\n  "camera": [%s, %s, %s, %s],\n  "color": "color.png",\n  "depth": "depth.png",\n  "depth_scale": %s\n}\n' \
  "$fx" "$fy" "$cx" "$cy" "$scale" >"$corpus/fuzz_frame_json/seed-ycbv.json"

# YCB-Video meta: the four variables read, in three MATLAB file versions.
seeds ycbv-meta "$ycbv/0000/000001-meta.mat" "$corpus/fuzz_ycbv_meta"

# BOP scene: the entries of image 3 of LM-O's scene_camera, scene_gt and scene_gt_info.
bop=$data/lmo_subset/data/bop/lmo/test/000002
entry() { printf '{\n%s\n}\n' "$(grep -m1 '^  "3":' "$1" | sed 's/,$//')"; }
{
  entry "$bop/scene_camera.json"
  printf '%s' "$separator"
  entry "$bop/scene_gt.json"
  printf '%s' "$separator"
  entry "$bop/scene_gt_info.json"
} >"$corpus/fuzz_bop_scene/seed-lmo"
entry "$bop/scene_camera.json" >"$corpus/fuzz_bop_scene/seed-lmo-camera-only"

# BOP task files: targets of the LM-O image (one per object of its ground truth; first byte 0) and a results CSV of two
# estimates (first byte 1).
{
  printf '\0['
  grep -m1 '^  "3":' "$bop/scene_gt.json" | grep -o '"obj_id": [0-9]*' | sed 's/"obj_id": \([0-9]*\)/{"im_id": 3, "inst_count": 1, "obj_id": \1, "scene_id": 2}/' |
    paste -sd, -
  printf ']\n'
} >"$corpus/fuzz_bop_task/seed-targets"
printf '\1scene_id,im_id,obj_id,score,R,t,time\n2,3,1,0.5,1 0 0 0 1 0 0 0 1,10 -20 800,0.4\n2,3,5,0.25,0 -1 0 1 0 0 0 0 1,1.5 2 950.25,0.4\n' \
  >"$corpus/fuzz_bop_task/seed-results"

# PCD: a crop of PCL's organized table scene, and the first points of the cut-out milk carton (xyz, and xyz rgba).
for cloud in milk_cartoon_all_small_clorox milk_color milk; do
  seeds pcd "$data/pcl_milk_scene/test/$cloud.pcd" "$corpus/fuzz_pcd"
done

# Pose JSON: the first ground-truth pose of YCB-Video video 0000.
awk '!/^#/ { printf "{\"camera_from_object\": [[%s, %s, %s, %s], [%s, %s, %s, %s], [%s, %s, %s, %s], [0, 0, 0, 1]]}\n",
             $4, $5, $6, $13, $7, $8, $9, $14, $10, $11, $12, $15; exit }' \
  "$data/ycbv_subset/derived/gt_0000.txt" >"$corpus/fuzz_pose_json/seed-ycbv.json"

# Meshes: trimmed real OBJs (YCB-Video's banana, YCB's cracker box) and an LM-O PLY, then fewer faces of the banana
# in the formats assimp writes and OFF (ecv_fuzz_seeds); each input starts with fuzz_mesh's extension digit.
banana=$data/ycbv_subset/models/011_banana
trim_obj 40 "$banana/textured_simple.obj" >"$work/banana.obj"
trim_obj 12 "$banana/textured_simple.obj" >"$work/banana-12.obj"
trim_obj 40 "$data/ycbv_subset/ycb_google16k_textured/003_cracker_box_textured.obj" >"$work/cracker_box.obj"
trim_ply 40 "$data/lmo_subset/data/bop/lmo/models/obj_000001.ply" >"$work/ape.ply"
for mesh in banana.obj cracker_box.obj; do { printf 0; cat "$work/$mesh"; } >"$corpus/fuzz_mesh/seed-$mesh"; done
{ printf 1; cat "$work/ape.ply"; } >"$corpus/fuzz_mesh/seed-ape.ply"
seeds mesh-formats "$work/banana-12.obj" "$corpus/fuzz_mesh"

# Mesh blobs: the trimmed banana with its material and texture (capped to 8 pixels), the trimmed ape with vertex
# colours.
cp "$banana/textured_simple.obj.mtl" "$banana/texture_map.png" "$work/"
sed -i 's|^mtllib .*|mtllib textured_simple.obj.mtl|' "$work/banana.obj"
seeds mesh-blob "$work/banana.obj" "$corpus/fuzz_mesh_blob/seed-banana"
seeds mesh-blob "$work/ape.ply" "$corpus/fuzz_mesh_blob/seed-ape"

# ONI: two frames of YCB-Video video 0000, cropped to 16 x 12, as `ecvpose record` writes a recording.
seeds oni "$ycbv/0000/000001-color.png" "$ycbv/0000/000001-depth.png" "$corpus/fuzz_oni/seed-ycbv.oni"

# Serve requests: the lines of fuzz/corpus/serve_request (tests/recognize/serve_request_test.cpp runs the target over
# them in every ctest run).
for line in "$(dirname "$0")"/corpus/serve_request/*; do cp "$line" "$corpus/fuzz_serve_request/seed-$(basename "$line")"; done

for target_dir in "$corpus"/fuzz_*; do
  echo "corpus: $(basename "$target_dir"): $(find "$target_dir" -name 'seed-*' | wc -l) seeds," \
    "$(du -sk "$target_dir" | cut -f1) KB"
done
