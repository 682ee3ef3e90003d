// A pose file (JSON with a 4x4 "camera_from_object") read by ReadPoseFile.

#include "fuzz_util.h"
#include "io/pose_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = (ecv::fuzz::ScratchDir() / "pose.json").string();
  ecv::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::ReadPoseFile(path); });
  return 0;
}
