// A .pcd file (through PCL's reader) as LoadFrame reads an organized cloud and ReadPcdPoints any cloud.

#include "fuzz_util.h"
#include "io/frame_io.h"
#include "io/points_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  ecv::FrameSpec spec;
  spec.positional = (ecv::fuzz::ScratchDir() / "cloud.pcd").string();
  ecv::fuzz::WriteFile(spec.positional, std::string(reinterpret_cast<const char*>(data), size));
  std::vector<std::string> warnings;
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::LoadFrame(spec, &warnings); });
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::ReadPcdPoints(spec.positional); });
  return 0;
}
