#!/usr/bin/env bash
# Builds a library that many tests read, once per ctest run (the demo_library and ycbv_library fixtures of
# tests/CMakeLists.txt) instead of once in each test's process: as the tests would build it, under a temporary name
# renamed into place when complete, so that a failed build leaves no library behind.
#   build_test_library.sh demo|ycbv ECVPOSE SOURCE_DIR DATA_DIR OUT.sqlite
set -euo pipefail
[ $# -eq 5 ] || { echo "usage: build_test_library.sh demo|ycbv ECVPOSE SOURCE_DIR DATA_DIR OUT.sqlite" >&2; exit 2; }
kind=$1 ecvpose=$2 source=$3 data=$4 out=$5
mkdir -p "$(dirname "$out")"
rm -f "$out" "$out-wal" "$out-shm" "$out.partial"
case $kind in
  # The demo library as scripts/demo builds it; the 7 textured YCB models as recognize_bench reads them.
  demo) "$ecvpose" modeldb build "$source/models/meshes" --views 40 --distance 0.9 --db "$out.partial" ;;
  ycbv) ECVPOSE=$ecvpose ECVPOSE_DATA_DIR=$data "$source/scripts/build_ycbv_library" "$out.partial" --views 40 \
          --distance 0.9 ;;
  *) echo "build_test_library.sh: no library kind \"$kind\" (demo or ycbv)" >&2; exit 2 ;;
esac
mv "$out.partial" "$out"
