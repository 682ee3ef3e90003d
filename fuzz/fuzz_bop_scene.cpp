// A BOP scene image "SCENE_DIR:3" read by LoadFrame: the input is scene_camera.json, scene_gt.json and
// scene_gt_info.json joined by kPartSeparator (an empty part leaves that file out), beside good rgb/ and depth/ PNGs.

#include "fuzz_util.h"
#include "io/frame_io.h"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  const fs::path& scene = ecv::fuzz::ScratchDir();
  fs::create_directories(scene / "rgb");
  fs::create_directories(scene / "depth");
  ecv::fuzz::WriteGoodImages(scene / "rgb" / "000003.png", scene / "depth" / "000003.png");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fs::path& scene = ecv::fuzz::ScratchDir();
  const std::vector<std::string> parts = ecv::fuzz::SplitParts(data, size, 3);
  const char* const names[] = {"scene_camera.json", "scene_gt.json", "scene_gt_info.json"};
  for (size_t i = 0; i < parts.size(); ++i) {
    fs::remove(scene / names[i]);
    if (!parts[i].empty()) ecv::fuzz::WriteFile(scene / names[i], parts[i]);
  }
  ecv::FrameSpec spec;
  spec.positional = scene.string() + ":3";
  std::vector<std::string> warnings;
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::LoadFrame(spec, &warnings); });
  return 0;
}
