// An ONI recording as CheckOniFile walks it before OpenNI2's file driver, which trusts the file's sizes, may read it.

#include "camera/oni_check.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = (ecv::fuzz::ScratchDir() / "recording.oni").string();
  ecv::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  ecv::fuzz::ExpectOnlyInputErrors([&] { ecv::CheckOniFile(path); });
  return 0;
}
