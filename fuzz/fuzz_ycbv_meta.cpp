// A YCB-Video frame prefix whose -meta.mat (MATLAB file, read with matio) is the input, beside good -color.png and
// -depth.png, read by LoadFrame.

#include "fuzz_util.h"
#include "io/frame_io.h"

namespace {

std::string Prefix() {
  return (ecv::fuzz::ScratchDir() / "000001").string();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  ecv::fuzz::WriteGoodImages(Prefix() + "-color.png", Prefix() + "-depth.png");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ecv::FrameSpec spec;
  spec.positional = Prefix();
  ecv::fuzz::WriteFile(Prefix() + "-meta.mat", std::string(reinterpret_cast<const char*>(data), size));
  std::vector<std::string> warnings;
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::LoadFrame(spec, &warnings); });
  return 0;
}
