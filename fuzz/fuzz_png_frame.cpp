// A frame given by flags: --color and --depth PNGs (the input: colour PNG, kPartSeparator, depth PNG), with a fixed
// depth scale and camera, read by LoadFrame.

#include "fuzz_util.h"
#include "io/frame_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = ecv::fuzz::SplitParts(data, size, 2);
  ecv::FrameSpec spec;
  spec.color_path = (ecv::fuzz::ScratchDir() / "color.png").string();
  spec.depth_path = (ecv::fuzz::ScratchDir() / "depth.png").string();
  spec.depth_scale = 10000.0;
  spec.camera = "1066.778,1067.487,312.9869,241.3109";
  ecv::fuzz::WriteFile(spec.color_path, parts[0]);
  ecv::fuzz::WriteFile(spec.depth_path, parts[1]);
  std::vector<std::string> warnings;
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::LoadFrame(spec, &warnings); });
  return 0;
}
