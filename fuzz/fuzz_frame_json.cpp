// A frame JSON (the input) naming good PNGs beside it ("color.png", "depth.png"), read by LoadFrame.

#include "fuzz_util.h"
#include "io/frame_io.h"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  ecv::fuzz::WriteGoodImages(ecv::fuzz::ScratchDir() / "color.png", ecv::fuzz::ScratchDir() / "depth.png");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ecv::FrameSpec spec;
  spec.positional = (ecv::fuzz::ScratchDir() / "frame.json").string();
  ecv::fuzz::WriteFile(spec.positional, std::string(reinterpret_cast<const char*>(data), size));
  std::vector<std::string> warnings;
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::LoadFrame(spec, &warnings); });
  return 0;
}
